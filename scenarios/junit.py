"""A JUnit XML report of scenario outcomes: one test case per scenario, its failed runs in the failure.

Each case's `classname` is its file's path (relative to the working directory when below it, the
suffix dropped, `/` as `.`), so two files of one name in different folders stay apart; `time` is the
wall time of its runs."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path


def classname(path: str) -> str:
    p = Path(path).resolve()
    try:
        p = p.relative_to(Path.cwd())
    except ValueError:
        pass
    text = p.as_posix().lstrip("/")
    text = text[: -len(".scenario.toml")] if text.endswith(".scenario.toml") else text
    return text.replace("/", ".")


def write_junit(path: str, outcomes: list) -> None:
    from arena.scenarios.runner import wilson

    suite = ET.Element("testsuite", name="arena-scenarios", tests=str(len(outcomes)))
    suite.set("failures", str(sum(not o.passed for o in outcomes)))
    suite.set("time", f"{sum(v.seconds for o in outcomes for v in o.verdicts):.3f}")
    for o in outcomes:
        seconds = sum(v.seconds for v in o.verdicts)
        case = ET.SubElement(
            suite, "testcase", classname=classname(o.scenario.path), name=o.scenario.name, time=f"{seconds:.3f}"
        )
        n = len(o.verdicts)
        lo, hi = wilson(o.passed_runs, n)
        summary = f"{o.passed_runs}/{n} runs passed, 95 % CI {lo:.2f}-{hi:.2f}, min_pass {o.scenario.spec.min_pass:g}"
        ET.SubElement(case, "system-out").text = summary
        if not o.passed:
            lines = [
                f"seed {v.seed}: {f.name} at tick {f.tick}: {f.detail}; replay: {v.replay_command()}"
                for v in o.verdicts
                for f in v.failures
            ]
            fail = ET.SubElement(case, "failure", message=summary)
            fail.text = "\n".join(lines)
    ET.ElementTree(suite).write(path, encoding="utf-8", xml_declaration=True)
