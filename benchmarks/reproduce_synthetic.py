"""Print the reproduction study's main table from a results folder.

    neurocur run reproduction --out results/reproduction
    python benchmarks/reproduce_synthetic.py results/reproduction [--markdown]

The table is :func:`neurocur.analysis.stats.reproduction.study_table` (its module docstring
defines the rows, the columns and the random-switching twins).
"""

from __future__ import annotations

import argparse

import pandas as pd

from neurocur.analysis.stats.reproduction import markdown, study_table


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("results", help="results folder of neurocur/experiments_data/reproduction.toml")
    parser.add_argument("--markdown", action="store_true", help="print a Markdown table")
    args = parser.parse_args(argv)
    table = study_table(args.results)
    with pd.option_context("display.width", 250, "display.max_columns", None):
        print(markdown(table) if args.markdown else table.to_string())


if __name__ == "__main__":
    main()
