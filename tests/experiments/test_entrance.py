"""The experiment entrance's three passes: resolve reads every file once, expand is pure, build
makes each condition once; an experiment file is followed through each module once, in order."""

from __future__ import annotations

import sys
from collections import Counter
from pathlib import Path

from neurocur.experiments import load_experiment
from neurocur.experiments.build import build
from neurocur.experiments.expand import expand
from neurocur.experiments.resolve import resolve
from neurocur.tables import shipped_files


def trace(call):
    """The ``neurocur.experiments`` modules whose own code ``call()`` runs, in order (a module
    entered again after another counts again; the constructors ``dataclass`` writes are left
    out), and the files ``neurocur.tables.load_toml`` reads, with their counts."""
    modules, files = [], Counter()

    def profile(frame, event, arg):
        if event != "call" or frame.f_code.co_filename == "<string>" or frame.f_code.co_name == "<module>":
            return  # a module's import is not a pass of the entrance (it runs here only when nothing imported it yet)
        name = frame.f_globals.get("__name__", "")
        if name == "neurocur.tables" and frame.f_code.co_name == "load_toml":
            files[Path(frame.f_locals["path"]).resolve()] += 1
        if name.startswith("neurocur.experiments") and (not modules or modules[-1] != name):
            modules.append(name)

    sys.setprofile(profile)
    try:
        result = call()
    finally:
        sys.setprofile(None)
    return result, [m.rpartition(".")[2] for m in modules], files


def test_the_entrance_enters_each_pass_once_in_order_and_reads_each_file_once():
    # lc_models extends synthetic and names five circuit files, two of which extend cd_misfa. The shipped
    # files are told apart (experiment or invariance demo) once per process, by reading each: done first here,
    # so that the test does not depend on whether an earlier test in the session did it
    shipped_files("experiment")
    exp, modules, files = trace(lambda: load_experiment("lc_models", sets=["HPC.threshold=0.25"]))
    assert modules == ["spec", "resolve", "expand", "build"]
    assert len(exp.conditions) == 5
    assert set(files.values()) == {1}, files  # every file once, however many conditions name it
    names = {p.name for p in files}
    assert {"lc_models.toml", "synthetic.toml", "cd_misfa.toml", "lc_softmax.toml"} <= names


def test_a_sweep_is_expanded_without_reading_and_built_once_per_point():
    resolved = resolve("sweep_pfc", sets=["PFC.discount=0.5,0.9"], runs=1)
    plans, modules, files = trace(lambda: expand(resolved))
    assert modules == ["expand"] and not files
    assert [p.point for p in plans] == [{"PFC.alpha": a, "PFC.discount": d}
                                        for a in resolved.sweep["PFC.alpha"].value for d in (0.5, 0.9)]
    exp, modules, files = trace(lambda: build(resolved, plans))
    assert modules == ["build"] and not files
    assert list(exp.conditions) == [p.label for p in plans]
    assert exp.conditions[plans[-1].label].circuit.specs["PFC"].params.discount == 0.9


def test_the_resolved_table_remembers_where_each_value_came_from(tmp_path):
    base = tmp_path / "base.toml"
    base.write_text('extends = "synthetic"\n[params]\n"HPC.threshold" = 0.4\n')
    mine = tmp_path / "mine.toml"
    mine.write_text('extends = "base.toml"\n[conditions.a.params]\n"LC.decay" = 0.9\n')
    resolved = resolve(mine, sets=["EC.n_pca=4"])
    assert (resolved.params["HPC.threshold"].source, resolved.params["HPC.threshold"].key) == (base, "params.HPC.threshold")
    assert resolved.params["HPC.n_states"].source.name == "synthetic.toml"
    assert resolved.conditions["a"].params["LC.decay"].key == "conditions.a.params.LC.decay"
    assert resolved.set_params["EC.n_pca"].source == "--set EC.n_pca"
    assert [e.source.name for e in resolved.world] == ["synthetic.toml", "base.toml", "mine.toml"]


def test_the_command_line_follows_an_experiment_file_through_each_module_once(monkeypatch):
    from neurocur.cli import main
    from neurocur.experiments import runner

    built = []

    def stop(exp, out, **kwargs):  # the runs are the runner's: stop once the conditions are built
        built.append(exp)
        raise ValueError("stopped before the runs")

    monkeypatch.setattr(runner, "run_experiment", stop)
    status, modules, _ = trace(lambda: main(["run", "sweep_pfc", "--set", "PFC.discount=0.5,0.9", "--runs", "1",
                                             "--scheduler", "local"]))
    assert status == 2 and len(built[0].conditions) == 6
    # the executor first (a local pool would start its fork server here), then the three passes
    assert modules == ["executors", "cluster", "experiments", "spec", "resolve", "expand", "build"]
