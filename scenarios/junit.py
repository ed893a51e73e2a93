"""A JUnit XML report of scenario outcomes: one test case per scenario, its failed runs in the failure."""

from __future__ import annotations

import xml.etree.ElementTree as ET
from pathlib import Path


def write_junit(path: str, outcomes: list) -> None:
    from arena.scenarios.runner import wilson

    suite = ET.Element("testsuite", name="arena-scenarios", tests=str(len(outcomes)))
    suite.set("failures", str(sum(not o.passed for o in outcomes)))
    for o in outcomes:
        case = ET.SubElement(suite, "testcase", classname=Path(o.scenario.path).name, name=o.scenario.name)
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
