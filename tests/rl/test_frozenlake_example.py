"""examples/rl_frozenlake.py (docs/hypotheses.md, entry 12) runs its four conditions: count novelty
through the counts path, which takes a pass per step (``frames=1``) and refuses any other."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]


def test_frozenlake_example_runs_every_condition(tmp_path):
    env = dict(os.environ, MPLBACKEND="Agg",
               PYTHONPATH=os.pathsep.join(filter(None, [str(ROOT), os.environ.get("PYTHONPATH")])))
    result = subprocess.run([sys.executable, str(ROOT / "examples/rl_frozenlake.py"), "--seeds", "2", "--steps", "400",
                             "--figure", str(tmp_path / "f.png")], cwd=tmp_path, env=env, capture_output=True,
                            text=True, timeout=300)
    assert result.returncode == 0, result.stderr[-2000:]
    table = result.stdout.splitlines()
    for condition in ("no bonus", "count novelty", "surprise", "learning progress"):
        assert sum(line.strip().startswith(condition) for line in table) == 1 + (condition != "no bonus") * 2
    assert (tmp_path / "f.png").stat().st_size > 0
