"""One line on stderr when numba compiles the kernels (an empty on-disk cache), and none when it loads them."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

from neurocur.learn._compiling import MESSAGE

ROOT = Path(__file__).resolve().parents[2]
FIT = "import numpy as np; from neurocur.learn import MCA; MCA(1).fit(np.eye(3) * 0.5); print('fitted')"


def _run(cache_dir: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHONPATH": str(ROOT), "NUMBA_CACHE_DIR": str(cache_dir)}
    return subprocess.run([sys.executable, "-c", FIT], capture_output=True, text=True, timeout=300, env=env, cwd=ROOT)


def test_the_message_is_printed_exactly_when_numba_compiles(tmp_path):
    cold = _run(tmp_path)  # an empty cache: numba compiles the MCA kernel (and writes the cache)
    assert cold.returncode == 0, cold.stderr[-2000:]
    assert cold.stderr == MESSAGE + "\n" and cold.stdout == "fitted\n"  # once, however many kernels compile
    assert any(tmp_path.rglob("*.nbi"))
    warm = _run(tmp_path)  # the same cache: loaded, not compiled
    assert warm.returncode == 0 and warm.stderr == "" and warm.stdout == "fitted\n"


def test_a_child_of_the_announcing_command_stays_silent(tmp_path):
    """`neurocur run` names itself in its children's environment: the fork server, which compiles the
    same kernels as the command's pre-flight, does not print the line a second time."""
    from neurocur.experiments.processes import COMPILING_ANNOUNCER
    from neurocur.learn._compiling import ANNOUNCER

    assert COMPILING_ANNOUNCER == ANNOUNCER
    env = {**os.environ, "PYTHONPATH": str(ROOT), "NUMBA_CACHE_DIR": str(tmp_path), ANNOUNCER: "1"}
    child = subprocess.run([sys.executable, "-c", FIT], capture_output=True, text=True, timeout=300, env=env, cwd=ROOT)
    assert child.returncode == 0 and child.stderr == "" and child.stdout == "fitted\n"
    assert any(tmp_path.rglob("*.nbi"))  # it did compile
