"""The base install and the extras (pyproject.toml, :mod:`neurocur.config.extras`).

Two checks stand in for a fresh ``pip install .`` (minutes, and the network): the base
dependencies are resolved transitively through the installed packages' own metadata, and the
synthetic experiment and its figures are run in a subprocess in which MuJoCo, dask,
distributed and pygame cannot be imported; the same subprocess shows that the features that
need them name their extra.
"""

from __future__ import annotations

import importlib.metadata
import os
import subprocess
import sys
import textwrap
import tomllib
from pathlib import Path

import pytest
from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

from neurocur.config import MissingExtra, extra

ROOT = Path(__file__).resolve().parents[2]
PROJECT = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
#: the modules the base install must not need, and their distributions (gymnasium's is pygame-ce)
HEAVY = {"mujoco", "dask", "distributed", "pygame"}
HEAVY_DISTRIBUTIONS = HEAVY | {"pygame-ce"}


def _requires(name: str, extras: frozenset[str]) -> list[tuple[Requirement, frozenset[str]]]:
    """The requirements of distribution ``name`` installed with ``extras`` (neurocur's from pyproject)."""
    if name == "neurocur":
        texts = PROJECT["dependencies"] + [r for e in sorted(extras) for r in PROJECT["optional-dependencies"][e]]
        marker_extras = {""}
    else:
        texts = importlib.metadata.requires(name) or []
        marker_extras = {"", *extras}
    out = []
    for req in map(Requirement, texts):
        if req.marker is None or any(req.marker.evaluate({"extra": e}) for e in marker_extras):
            out.append((req, frozenset(req.extras)))
    return out


def closure(extras: set[str] = frozenset()) -> tuple[set[str], set[str]]:
    """The distributions ``pip install .[extras]`` installs, walked through installed metadata, and
    those of them not installed here (their own requirements are then unknown)."""
    seen: set[tuple[str, frozenset[str]]] = set()
    names, missing = set(), set()
    todo = [("neurocur", frozenset(extras))]
    while todo:
        name, ex = todo.pop()
        if (name, ex) in seen:
            continue
        seen.add((name, ex))
        for req, req_extras in _requires(name, ex):
            dep = canonicalize_name(req.name)
            names.add(dep)
            try:
                importlib.metadata.distribution(dep)
            except importlib.metadata.PackageNotFoundError:
                if dep != "neurocur":
                    missing.add(dep)
                    continue
            todo.append((dep, req_extras))
    names.discard("neurocur")
    return names, missing


def test_base_install_pulls_in_no_heavy_package():
    names, missing = closure()
    assert not missing, f"base dependencies not installed here, so not checked: {missing}"
    assert {"numpy", "numba", "llvmlite", "gymnasium", "statsmodels", "pyarrow"} <= names  # walked transitively
    assert not names & HEAVY_DISTRIBUTIONS, names & HEAVY_DISTRIBUTIONS


@pytest.mark.parametrize(("extras", "wanted"), [
    ({"icub"}, {"mujoco", "icub-models"}),
    ({"icub-body"}, {"mujoco", "icub-models"}),
    ({"cluster"}, {"dask", "distributed"}),
    ({"gym"}, {"gymnasium", "pygame-ce"}),
    ({"rl"}, {"stable-baselines3", "torch"}),
    ({"fit"}, {"sbi", "torch"}),
    ({"all"}, {"mujoco", "icub-models", "distributed", "pygame-ce", "stable-baselines3", "sbi"}),
    ({"test"}, {"mujoco", "icub-models", "distributed", "pygame-ce", "sbi", "torch", "stable-baselines3", "pytest", "mkdocs",
                "import-linter"}),
])
def test_each_extra_installs_its_packages(extras, wanted):
    names, _ = closure(extras)
    assert wanted <= names, wanted - names


def test_a_missing_module_names_the_extra():
    with pytest.raises(MissingExtra) as info, extra("cluster", "a dask cluster (--scheduler)"):
        import neurocur_no_such_module  # noqa: F401
    message = str(info.value)
    assert message == ("a dask cluster (--scheduler) needs the Python package 'neurocur_no_such_module', which is not "
                       "installed: pip install 'neurocur[cluster]'")
    assert isinstance(info.value, ValueError) and isinstance(info.value, ImportError)  # exit 2; probes catch it
    assert info.value.name == "neurocur_no_such_module"


def test_an_installed_module_passes():
    with extra("cluster", "anything"):
        import json
    assert json.dumps(1) == "1"


BLOCKER = f"""
import sys

class _NotInstalled:
    '''{sorted(HEAVY)} cannot be imported, as if they were not installed.'''

    def find_spec(self, name, path=None, target=None):
        if name.partition(".")[0] in {sorted(HEAVY)}:
            raise ModuleNotFoundError(f"No module named {{name!r}}", name=name)
        return None

sys.meta_path.insert(0, _NotInstalled())
"""


@pytest.fixture(scope="module")
def light(tmp_path_factory):
    """Run ``neurocur`` with the heavy packages unimportable (in every process it starts too)."""
    root = tmp_path_factory.mktemp("light")
    (root / "site").mkdir()
    (root / "site" / "sitecustomize.py").write_text(textwrap.dedent(BLOCKER))
    env = {**os.environ, "PYTHONPATH": os.pathsep.join([str(root / "site"), str(ROOT)]),
           "NEUROCUR_CACHE": str(root / "cache"), "MPLBACKEND": "Agg"}

    def run(*args, code: str | None = None):
        argv = ["-c", code] if code else ["-m", "neurocur.cli", *args]
        return subprocess.run([sys.executable, *argv], env=env, cwd=root, capture_output=True, text=True,
                              timeout=600)

    run.root = root
    return run


def test_the_blocker_works(light):
    done = light(code="import mujoco")
    assert done.returncode == 1 and "ModuleNotFoundError: No module named 'mujoco'" in done.stderr


def test_the_base_install_runs_the_synthetic_experiment_and_its_figures(light):
    out = light.root / "synthetic"
    done = light("run", "synthetic", "--runs", "1", "--steps", "20000", "--jobs", "1", "--out", str(out))
    assert done.returncode == 0, done.stderr
    assert "S-A first" in done.stdout
    assert len(list((out / "runs").glob("*/run-000"))) == 3  # curious, random_switching, literal
    done = light("figures", str(out), "--out", str(light.root / "figures"))
    assert done.returncode == 0, done.stderr
    assert len(list((light.root / "figures").glob("*.png"))) >= 4


@pytest.mark.parametrize(("args", "extra_name"), [
    (("run", "synthetic", "--runs", "1", "--steps", "1000", "--scheduler", "local"), "cluster"),
    (("run", "icub", "--runs", "1", "--steps", "1000"), "icub"),
    (("run", "gym_classic", "--runs", "1", "--steps", "1000"), "gym"),
])
def test_a_feature_without_its_extra_exits_2_naming_it(light, tmp_path, args, extra_name):
    done = light(*args, "--out", str(tmp_path / "out"))
    assert done.returncode == 2, done.stderr
    assert done.stderr.count("\n") == 1 and done.stderr.endswith(f"pip install 'neurocur[{extra_name}]'\n"), done.stderr
