"""The neurocur command end to end: run, figures, omega, and its error messages."""

import json
from pathlib import Path

import numpy as np
import pytest

from neurocur.cli import main
from neurocur.contexts.sources import paper_source

SYNTHETIC = str(Path(__file__).resolve().parents[2] / "neurocur" / "experiments_data" / "synthetic.toml")


def test_run_then_figures(tmp_path, capsys):
    out = tmp_path / "res"
    rc = main(["run", SYNTHETIC, "--runs", "2", "--steps", "2000", "--jobs", "2", "--out", str(out),
               "--condition", "curious", "--set", "HPC.threshold=0.3", "--no-progress"])
    printed = capsys.readouterr().out
    assert rc == 0
    assert f"results: {out}" in printed
    for row in ("S-A first", "S-B second", "S-C third", "exact S-A→S-B→S-C", "S-D stored", "modules per run"):
        assert row in printed
    assert "curious" in printed and "random_switching" not in printed
    files = sorted(str(p.relative_to(out)) for p in out.rglob("*") if p.is_file())
    assert files == ["config.toml", *(f"runs/curious/run-00{i}/{n}" for i in range(2)
                                      for n in ("episodes.parquet", "modules.parquet", "run.json")), "summary.json"]
    assert json.loads((out / "summary.json").read_text())["n_runs"] == {"curious": 2}

    assert main(["figures", str(out)]) == 0
    paths = [Path(line) for line in capsys.readouterr().out.splitlines()]
    assert paths and all(p.is_file() and p.parent == out / "figures" for p in paths)
    assert {p.suffix for p in paths} == {".png", ".csv"} and out / "figures" / "index.csv" in paths
    assert {"order_counts.png", "learning_time.png", "cumulative_error_curious.png",
            "invariance.png"} <= {p.name for p in paths}                     # Figure 5 too, by its own run
    assert (out / "figures" / "invariance.json").is_file()


@pytest.mark.parametrize("argv, message", [
    (["run", SYNTHETIC, "--set", "HPC.threshold=abc"], "--set HPC.threshold: expected a number > 0, got 'abc'"),
    (["run", SYNTHETIC, "--condition", "lazy"], "--condition lazy: expected one of curious, random_switching"),
    (["run", SYNTHETIC, "--set", "world.normalise=pixel"], "--set: key 'world.normalise': expected one of 'global', 'image', got 'pixel'"),
    (["run", "nowhere.toml"], "nowhere.toml: expected an existing TOML file"),
    (["omega"], "give either FILE.npy or --experiment FILE"),
    (["omega", "missing.npy"], "expected an existing .npy file, got 'missing.npy'"),
    (["omega", "--experiment", SYNTHETIC, "--context", "C9"], "--context: expected one of C1, C2, C3, C4, C5"),
])
def test_bad_values_exit_2_with_one_line(argv, message, capsys):
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err and err.count("\n") == 1


def _files(tmp: Path) -> dict[str, str]:
    (tmp / "a_file").write_text("not a folder\n")
    (tmp / "binary.toml").write_bytes(b"\x80\x81\x00\xff")
    (tmp / "text.npy").write_text("1 2 3\n")
    np.savez(tmp / "archive.npz", a=np.zeros((5, 2)))
    return {"TMP": str(tmp), "FILE": str(tmp / "a_file"), "BINARY": str(tmp / "binary.toml"),
            "TEXT": str(tmp / "text.npy"), "NPZ": str(tmp / "archive.npz")}


@pytest.mark.parametrize("argv, message", [
    (["run", "{TMP}"], "{TMP}: expected a TOML file, got a directory"),
    (["run", "{BINARY}"], "{BINARY}: expected a TOML file (UTF-8 text), got a binary file"),
    (["run", SYNTHETIC, "--out", "{FILE}"], "results folder {FILE}: expected a folder, got a file"),
    (["run", SYNTHETIC, "--out", "{FILE}/sub"], "results folder {FILE}/sub: cannot create it (Not a directory)"),
    (["run", SYNTHETIC, "--out", "/proc/neurocur-results"], "results folder /proc/neurocur-results: cannot create it"),
    (["figures", "{TMP}", "--out", "{FILE}"], "--out: expected a folder, got '{FILE}' (a file)"),
    (["figures", "{TMP}", "--out", "{FILE}/sub"], "--out: expected a folder, got '{FILE}/sub' (inside the file"),
    (["omega", "{TEXT}"], "omega: {TEXT}: expected a .npy array written by numpy.save, got a file numpy cannot read"),
    (["omega", "{NPZ}"], "omega: {NPZ}: expected a .npy array written by numpy.save, got a .npz archive"),
])
def test_files_and_folders_that_do_not_fit_exit_2_with_one_line(argv, message, tmp_path, capsys):
    names = _files(tmp_path)
    assert main([a.format(**names) for a in argv]) == 2
    err = capsys.readouterr().err
    assert message.format(**names) in err and "Traceback" not in err and err.count("\n") == 1


@pytest.mark.parametrize("argv, message", [
    (["run", SYNTHETIC, "--max-memory", "lots"], "argument --max-memory: expected a memory size such as 8G"),
    (["run", SYNTHETIC, "--runs", "0"], "argument --runs: expected a positive integer, got '0'"),
    (["run", SYNTHETIC, "--jobs", "two"], "argument --jobs: expected a positive integer, got 'two'"),
    (["omega", "x.npy", "--eta", "0.9"], "argument --eta: expected a number in (0, 0.5], got '0.9'"),
    (["dance"], "invalid choice: 'dance'"),
])
def test_bad_arguments_exit_2(argv, message, capsys):
    with pytest.raises(SystemExit) as info:
        main(argv)
    assert info.value.code == 2 and message in capsys.readouterr().err


def test_help_has_examples(capsys):
    with pytest.raises(SystemExit) as info:
        main(["--help"])
    text = capsys.readouterr().out
    assert info.value.code == 0
    for word in ("run", "figures", "omega", "examples:", "neurocur run synthetic"):
        assert word in text
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    assert "--set KEY=VALUE" in capsys.readouterr().out


def test_omega_of_a_file_and_of_contexts(tmp_path, capsys):
    np.save(tmp_path / "a.npy", paper_source("S-A"))
    assert main(["omega", str(tmp_path / "a.npy")]) == 0
    assert "Omega = 0.99332" in capsys.readouterr().out
    assert main(["omega", "--experiment", SYNTHETIC]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert [line.split()[:2] for line in lines] == [["C1", "S-A"], ["C2", "S-A"], ["C3", "S-B"], ["C4", "S-C"],
                                                   ["C5", "S-D"]]
    values = [float(line.split("=")[1].split()[0]) for line in lines]
    assert values[:4] == [0.99332, 0.99332, 0.99881, 0.9997] and values[4] > 0.999
    assert "redrawn every epoch: 10 draws joined; per draw mean 1.00000" in lines[4]  # S-D: Omega 1 per draw


def test_the_console_script_exits_with_the_status_of_main_and_freezes_the_collector(monkeypatch):
    import gc

    from neurocur import cli

    monkeypatch.setattr(cli, "main", lambda: 2)
    frozen = gc.get_freeze_count()
    try:
        with pytest.raises(SystemExit) as exit_:
            cli.command()
        assert exit_.value.code == 2
        assert gc.get_freeze_count() > frozen  # the objects alive at exit are left to the interpreter
    finally:
        gc.unfreeze()
