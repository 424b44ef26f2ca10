"""The neurocur command's help fits 100 columns, whatever the terminal, and its shell completion."""

from __future__ import annotations

import re

import pytest

from neurocur.cli import build_parser, main

SUBCOMMANDS = sorted(build_parser()._subparsers._group_actions[0].choices)


def _help(argv, capsys) -> str:
    with pytest.raises(SystemExit) as info:
        main([*argv, "--help"])
    assert info.value.code == 0
    return capsys.readouterr().out


def test_the_subcommands_are_the_documented_ones():
    assert set(SUBCOMMANDS) >= {"run", "figures", "omega", "invariance", "list", "fit", "recover", "compare", "sbi",
                                "completion"}


@pytest.mark.parametrize("argv", [[]] + [[name] for name in SUBCOMMANDS])
def test_every_help_fits_100_columns_on_a_wide_terminal(argv, capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "250")
    text = _help(argv, capsys)
    widths = [len(line) for line in text.splitlines()]
    assert max(widths) <= 100, text
    parser = build_parser()
    if argv:
        parser = parser._subparsers._group_actions[0].choices[argv[0]]
    words = " ".join(text.split())
    for prose in (parser.description, parser.epilog):  # wrapped, not cut: every word still there, in order
        if prose:
            assert " ".join(prose.replace("\\", "").split()) in words.replace(" \\", "")


def test_a_narrow_terminal_narrows_the_help(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "70")
    assert max(len(line) for line in _help(["run"], capsys).splitlines()) <= 70


def test_a_long_example_command_wraps_as_shell_continuation_lines(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "250")
    lines = _help(["fit"], capsys).splitlines()
    start = next(i for i, line in enumerate(lines) if line.startswith("  neurocur fit "))
    command = [lines[start]]
    while command[-1].endswith(" \\"):
        command.append(lines[start + len(command)])
    assert len(command) >= 2 and all(line.startswith("      ") for line in command[1:])
    joined = " ".join(line.removesuffix(" \\").strip() for line in command)
    assert joined == ("neurocur fit results/free_choice --experiment free_choice --condition learning_progress "
                      "--fit LC.gain --bounds LC.gain=0:60 --signal HPC=error --out results/fit")


def test_an_example_with_a_comment_column_keeps_its_column(capsys, monkeypatch):
    monkeypatch.setenv("COLUMNS", "80")
    lines = _help([], capsys).splitlines()
    i = next(i for i, line in enumerate(lines) if line.startswith("  neurocur run synthetic  "))
    column = re.match(r"\s*neurocur run synthetic\s+", lines[i]).end()
    assert lines[i + 1].startswith(" " * column) and lines[i + 1][column] != " "


@pytest.mark.parametrize("shell", ["bash", "zsh"])
def test_completion_prints_a_script_naming_the_subcommands(shell, capsys):
    assert main(["completion", shell]) == 0
    script = capsys.readouterr().out
    if shell == "bash":
        assert re.search(r"^complete .*-F _shtab_neurocur neurocur$", script, re.M)
        subcommands = re.search(r"_shtab_neurocur_subparsers=\(([^)]*)\)", script).group(1)
        assert sorted(subcommands.replace("'", "").split()) == SUBCOMMANDS
    else:
        assert script.startswith("#compdef neurocur")
        for name in SUBCOMMANDS:
            assert re.search(rf"^ +{name}:'", script, re.M)
    assert "--save-agent" in script and "--experiment" in script  # the subcommands' options too


def test_completion_refuses_an_unknown_shell(capsys):
    with pytest.raises(SystemExit) as info:
        main(["completion", "cmd.exe"])
    assert info.value.code == 2 and "invalid choice: 'cmd.exe'" in capsys.readouterr().err
