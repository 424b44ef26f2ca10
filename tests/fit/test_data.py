"""Behaviour tables: read from CSV, Parquet and results folders; bad data named in one line."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from neurocur.config import ConfigError
from neurocur.fit.data import read_behaviour

NAMES = ("C1", "C2", "C3")


def table():
    return pd.DataFrame({"dataset": ["a"] * 4 + ["b"] * 2, "episode": [0, 1, 2, 3, 0, 1],
                         "context": ["C1", "C1", "C3", "C2", 1, 1],
                         "decision": ["engage", "disengage", "disengage", "engage", 0, 1],
                         "error": [0.5, 0.4, 0.3, 0.2, 0.1, 0.0]})


@pytest.mark.parametrize("suffix", [".csv", ".parquet"])
def test_a_table_gives_one_data_set_per_dataset_label(tmp_path, suffix):
    path = tmp_path / f"b{suffix}"
    t = table().astype({"context": str, "decision": str})
    t.to_csv(path, index=False) if suffix == ".csv" else t.to_parquet(path)
    a, b = read_behaviour(path, NAMES, signals=["error"])
    assert (a.name, b.name) == ("a", "b")
    np.testing.assert_array_equal(a.contexts, [0, 0, 2, 1])
    np.testing.assert_array_equal(a.decisions, [0, 1, 1, 0])
    np.testing.assert_array_equal(a.next_contexts(3), [0, 2, 1, 1])
    np.testing.assert_array_equal(b.signals["error"], [0.1, 0.0])
    np.testing.assert_array_equal(b.next_contexts(3), [1, 2])


@pytest.mark.parametrize("change,key,said", [
    (lambda t: t.drop(columns="decision"), "decision", "got none"),
    (lambda t: t.assign(context=["C1", "C1", "C9", "C2", 1, 1]), "context", "'C9' in row 2"),
    (lambda t: t.assign(episode=[0, 2, 1, 3, 0, 1]), "episode", "episode 1 after episode 2"),
    (lambda t: t.assign(decision=["engage", "engage", "disengage", "engage", 0, 1]), "decision", "'engage' at episode 1"),
    (lambda t: t.assign(error=[0.5, None, 0.3, 0.2, 0.1, 0.0]), "error", "row 1"),
])
def test_bad_data_is_one_line_naming_file_column_and_what_was_expected(tmp_path, change, key, said):
    path = tmp_path / "bad.csv"
    change(table()).to_csv(path, index=False)
    with pytest.raises(ConfigError) as err:
        read_behaviour(path, NAMES, signals=["error"] if key == "error" else ())
    message = str(err.value)
    assert "\n" not in message and str(path) in message and f"'{key}'" in message and said in message


def test_free_choice_decisions_are_the_next_contexts(tmp_path):
    path = tmp_path / "choice.csv"
    pd.DataFrame({"dataset": "s", "episode": [0, 1, 2], "context": [0, 2, 1], "decision": [2, 1, 1]}).to_csv(path)
    (s,) = read_behaviour(path, NAMES, free_choice=True)
    np.testing.assert_array_equal(s.next_contexts(3), [2, 1, 1])
    pd.DataFrame({"dataset": "s", "episode": [0, 1, 2], "context": [0, 1, 1], "decision": [2, 1, 1]}).to_csv(path)
    with pytest.raises(ConfigError, match="context 2 chosen at episode 0, then context 1"):
        read_behaviour(path, NAMES, free_choice=True)


def test_a_missing_file_is_named(tmp_path):
    with pytest.raises(ConfigError, match="no such path"):
        read_behaviour(tmp_path / "none.csv", NAMES)
