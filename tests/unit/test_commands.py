"""Every sub-command is a module of arena/commands/ with `add_parser(sub)` and `run(args) -> int`,
and its help shows examples; arena/cli.py only dispatches to them."""

from __future__ import annotations

import pytest

from arena.cli import command, parser
from arena.commands import names


def test_every_command_module_is_a_sub_command_with_examples(capsys):
    subs = next(a for a in parser()._actions if a.dest == "command").choices
    assert set(subs) == set(names())
    for name in names():
        assert callable(command(name).run), name
        with pytest.raises(SystemExit):
            parser().parse_args([name, "--help"])
        assert "examples:" in capsys.readouterr().out, f"arena {name} --help shows no examples"


def test_cli_py_only_dispatches():
    from pathlib import Path

    import arena.cli

    source = Path(arena.cli.__file__).read_text()
    assert "add_argument(" not in source.replace('top.add_argument("--version"', "")
    assert len(source.splitlines()) < 150
