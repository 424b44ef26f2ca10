"""The recording contract (neurocur.contract): every registered region type, in its role, produces
the columns the analysis reads; probe names and end-of-run products are unique."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from neurocur.circuit import Circuit
from neurocur.config import ConfigError
from neurocur.contexts.synthetic import SyntheticWorld
from neurocur.contract import EPISODE_COLUMNS, MODULE_COLUMNS, require_columns
from neurocur.regions import REGIONS, Probe, Region, Signal

CIRCUIT = Path(__file__).resolve().parents[2] / "neurocur" / "circuits" / "cd_misfa.toml"
#: the role (region name in cd_misfa.toml) of each built-in type family
ROLES = {"sensory": "sensory", "ec": "EC", "hpc": "HPC", "vta": "VTA", "pfc": "PFC", "lc": "LC"}
DTYPES = {"float": np.float64, "int": np.int64, "bool": np.bool_}
BUILT_IN = [n for n in REGIONS.names() if n.split(".")[0] in ROLES]


def test_every_built_in_family_is_covered():
    assert {"sensory.world", "ec.incsfa", "hpc.roc", "vta.learning_progress", "vta.novelty", "pfc.lspi",
            "lc.epsilon_greedy"} <= set(BUILT_IN)


def _in_role(type_name, role):
    """cd_misfa.toml with ``role`` replaced by ``type_name``; a type that reads more than the role's edges
    deliver (e.g. the adaptive-gain LC reads VTA's dopamine) runs in the shipped circuit that declares it."""
    try:
        return Circuit.from_toml(CIRCUIT).replace(role, {"type": type_name})
    except ConfigError:
        shipped = (Circuit.from_toml(path) for path in sorted(CIRCUIT.parent.glob("*.toml")))
        return next(c for c in shipped if role in c.specs and c.specs[role].type_name == type_name)


@pytest.mark.parametrize("type_name", BUILT_IN)
def test_region_type_in_its_role_produces_the_contract(type_name):
    role = ROLES[type_name.split(".")[0]]
    circuit = _in_role(type_name, role)
    sim = circuit.build(SyntheticWorld(), seed=3).run(30_000)
    episodes, products = sim.episodes(), sim.products()
    for column in EPISODE_COLUMNS:
        assert column.name in episodes, f"{type_name} as {role}: no column {column.name!r}"
        if column.kind in DTYPES:
            assert episodes[column.name].dtype == DTYPES[column.kind], column.name
    modules = products["modules"]
    assert list(modules.columns) == [c.name for c in MODULE_COLUMNS] and (modules.dtypes == np.int64).all()
    assert len(products["library"]) == len(modules) == episodes["module_learned"].sum()


def test_require_columns_names_the_producing_role():
    table = pd.DataFrame({"da": [0.0]})
    require_columns(table, ["da"], needed_by="a figure")
    with pytest.raises(ValueError, match=r"a figure needs the column\(s\) 'ne_tonic' \(from LC\)"):
        require_columns(table, ["da", "ne_tonic"], needed_by="a figure")


@REGIONS.register("contract.shadow")
class Shadow(Region):
    """Reads VTA's dopamine and records a probe of the same name."""

    inputs = (Signal("da", "float64", ()),)
    probes = (Probe("da", "float", "a.u."),)

    def step(self, da):
        return ()

    def record(self):
        return (0.0,)


@REGIONS.register("contract.thief")
class Thief(Region):
    """Reads VTA's dopamine and claims HPC's end-of-run product."""

    inputs = (Signal("da", "float64", ()),)

    def step(self, da):
        return ()

    def products(self, events):
        return {"modules": None}


def _extended(tmp_path, type_name):
    path = tmp_path / "extra.toml"
    path.write_text(f'''extends = "{CIRCUIT}"
[regions.extra]
type = "{type_name}"
[[edges]]
from = "VTA"
signal = "da"
to = "extra"
''')
    return path


def test_a_second_probe_of_the_same_name_is_an_error(tmp_path):
    path = _extended(tmp_path, "contract.shadow")
    with pytest.raises(ConfigError, match=r"extra.toml: key 'regions.extra': expected probe names unique in the "
                                          r"circuit \('da' is recorded by region 'VTA'\), got a second probe 'da'"):
        Circuit.from_toml(path)


def test_two_regions_producing_one_product_is_an_error(tmp_path):
    sim = Circuit.from_toml(_extended(tmp_path, "contract.thief")).build(SyntheticWorld(), seed=0).run(100)
    with pytest.raises(ValueError, match="regions 'HPC' and 'extra' both produce the end-of-run product 'modules'"):
        sim.products()
