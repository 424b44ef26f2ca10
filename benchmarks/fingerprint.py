"""Fingerprints of the results tables of the shipped experiments, for a fixed seed.

    python benchmarks/fingerprint.py            # print the fingerprints
    python benchmarks/fingerprint.py --check    # compare with benchmarks/fingerprints.json
    python benchmarks/fingerprint.py --write    # record them (a deliberate change of results)

Runs ``neurocur/experiments_data/synthetic.toml`` (every condition) and ``neurocur/experiments_data/icub.toml`` (both
conditions) small, through the command line, and hashes every table of every run
(column names, dtypes and values, via ``pandas.util.hash_pandas_object``). A change that
alters any results table for the same seed changes a fingerprint: such a change must be
deliberate, recorded with ``--write`` in the same commit, and its statistics shown.

The versions of the packages that shape the numbers (MuJoCo renders the iCub world and moves its
objects; numba compiles the learners) are recorded beside each experiment's fingerprints. When
tables differ and so do the versions, ``--check`` says so: the iCub episodes are not the same
across MuJoCo releases (the cup of the topple context falls differently), so its tables are
reproducible bit for bit only under the recorded versions. So are the synthetic tables under numpy's
BLAS kernel: they were recorded with OpenBLAS's Haswell kernel, and its SkylakeX kernel (chosen on a
processor with AVX-512 unless ``OPENBLAS_CORETYPE`` says otherwise) gives other tables for the same seed.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import platform
import subprocess
import sys
import tempfile
from importlib.metadata import PackageNotFoundError, version
from pathlib import Path

import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
RECORD = ROOT / "benchmarks" / "fingerprints.json"
#: experiment file -> command-line settings of the small run
CASES = {
    "synthetic": ["synthetic", "--runs", "2", "--steps", "30000"],
    "icub": ["icub", "--runs", "2", "--steps", "8000", "--set", "HPC.threshold=1.5"],
}


#: the packages whose versions are recorded with the fingerprints
PACKAGES = ("numpy", "scipy", "pandas", "pyarrow", "numba", "llvmlite", "scikit-learn", "mujoco")


def environment() -> dict[str, str]:
    """Python's version, numpy's BLAS and its kernel (OpenBLAS picks one per processor, or as
    ``OPENBLAS_CORETYPE`` says; two kernels' matrix products differ in their last bits, and so do the
    tables), and the versions of :data:`PACKAGES` (``"absent"`` when one is not installed)."""
    import numpy  # noqa: F401  (loads the BLAS threadpoolctl reports)
    from threadpoolctl import threadpool_info

    found = {"python": platform.python_version()}
    blas = [i for i in threadpool_info() if i.get("user_api") == "blas"]
    found["blas"] = " ".join(str(blas[0].get(k)) for k in ("internal_api", "version", "architecture")) if blas else "absent"
    for name in PACKAGES:
        try:
            found[name] = version(name)
        except PackageNotFoundError:
            found[name] = "absent"
    return found


def table_hash(table: pd.DataFrame) -> str:
    """sha256 over the column names, the dtypes and the row hashes of ``table``."""
    h = hashlib.sha256()
    h.update(json.dumps([[str(c), str(t)] for c, t in table.dtypes.items()]).encode())
    h.update(pd.util.hash_pandas_object(table, index=False).to_numpy().tobytes())
    return h.hexdigest()[:16]


def fingerprints(name: str, args: list[str], jobs: int) -> dict[str, str]:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / name
        cmd = [sys.executable, "-m", "neurocur.cli", "run", *args, "--out", str(out), "--jobs", str(jobs),
               "--no-progress"]
        subprocess.run(cmd, cwd=ROOT, check=True, stdout=subprocess.DEVNULL)
        return {str(p.relative_to(out / "runs")): table_hash(pd.read_parquet(p))
                for p in sorted((out / "runs").glob("*/*/*.parquet"))}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    mode = parser.add_mutually_exclusive_group()
    mode.add_argument("--check", action="store_true", help="compare with the recorded fingerprints")
    mode.add_argument("--write", action="store_true", help="record the fingerprints")
    parser.add_argument("--only", choices=list(CASES), action="append", help="only this experiment")
    parser.add_argument("--jobs", type=int, default=2)
    args = parser.parse_args(argv)
    found = {name: fingerprints(name, CASES[name], args.jobs) for name in (args.only or CASES)}
    now = environment()
    if args.write:
        recorded = json.loads(RECORD.read_text()) if RECORD.is_file() else {}
        written = {**recorded, **found, "environment": {**recorded.get("environment", {}), **dict.fromkeys(found, now)}}
        RECORD.write_text(json.dumps(written, indent=2, sort_keys=True) + "\n")
        print(f"recorded {sum(map(len, found.values()))} table fingerprints in {RECORD}")
        return 0
    if args.check:
        recorded = json.loads(RECORD.read_text())
        bad = [f"{name}/{key}" for name, tables in found.items() for key in
               sorted(set(tables) | set(recorded.get(name, {}))) if tables.get(key) != recorded.get(name, {}).get(key)]
        for key in bad:
            print(f"differs: {key}")
        for name in sorted({key.split("/")[0] for key in bad}):
            then = recorded.get("environment", {}).get(name, {})
            moved = [f"{p} {then.get(p, 'not recorded')} -> {v}" for p, v in now.items() if then.get(p) != v]
            if moved:
                print(f"{name}: recorded under other versions ({', '.join(moved)}); a dependency may be the cause")
        print(f"{sum(map(len, found.values())) - len(bad)} tables identical, {len(bad)} differ")
        return 1 if bad else 0
    print(json.dumps(found, indent=2, sort_keys=True))
    return 0


if __name__ == "__main__":
    sys.exit(main())
