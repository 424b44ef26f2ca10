"""No silent degeneracy: a condition whose VTA reads the world's extrinsic reward (``vta.td``, ``vta.mixture``
with a nonzero weight) in a world that pays none is refused when the experiment is built, one line naming
the file, the key and what was expected; a rewarding world builds and pays the VTA. The shipped hypothesis
runs that compare reward-reading models (noisy_tv) run in a rewarding world."""

from __future__ import annotations

import numpy as np
import pytest

from neurocur.config import ConfigError
from neurocur.experiments import load_experiment, run_one


def experiment(tmp_path, condition: str, world: str = "") -> str:
    path = tmp_path / "exp.toml"
    path.write_text(f'extends = "synthetic"\nname = "t"\ncontrol = "reader"\n{world}\n'
                    f'[conditions.reader]\n{condition}\n', encoding="utf-8")
    return path


@pytest.mark.parametrize("condition, reader", [
    ('circuit = "vta_td"', "VTA (vta.td)"),
    ('circuit = "vta_mixture"', "VTA (vta.mixture)"),
    ('circuit = "vta_mixture"\nparams = { "VTA.weight" = 1.0 }', "VTA (vta.mixture)"),
])
@pytest.mark.parametrize("world", ["", "[world]\nrewards = [0, 0, 0, 0.0, 0]"])
def test_a_reward_reader_in_a_world_that_pays_none_is_refused(tmp_path, condition, reader, world):
    path = experiment(tmp_path, condition, world)
    with pytest.raises(ConfigError) as info:
        load_experiment(path)
    message = str(info.value)
    assert "\n" not in message and message.startswith(str(path))
    assert "'world.rewards'" in message and "conditions.reader" in message and reader in message


@pytest.mark.parametrize("condition", ['circuit = "vta_td"', 'circuit = "vta_mixture"'])
def test_a_reward_reader_in_a_rewarding_world_builds(tmp_path, condition):
    exp = load_experiment(experiment(tmp_path, condition, "[world]\nrewards = [0, 0, [1, 0], 0, 0]"))
    assert set(exp.conditions) == {"reader"}


def test_the_mixture_without_its_extrinsic_share_and_the_intrinsic_models_need_no_reward(tmp_path):
    exp = load_experiment(experiment(tmp_path, 'circuit = "vta_mixture"\nparams = { "VTA.weight" = 0.0 }'))
    assert exp.conditions["reader"].circuit.specs["VTA"].params.weight == 0.0
    load_experiment(experiment(tmp_path, 'circuit = "vta_surprise"'))


def test_the_noisy_tv_world_pays_the_td_vta():
    """Entry 3 compares TD with the intrinsic models: its world pays 1 per visit of C3 (S-B) and nothing
    elsewhere, and that reward reaches TD's dopamine: on the first episode DA = r, then
    DA = r + gamma V(c') - V(c) with V learned from DA (replayed here from the recorded contexts)."""
    exp = load_experiment("noisy_tv", steps=3000)
    ep = run_one(exp.conditions["td"], 0, 3000, exp.run_seed(0)).episodes
    paid = ep["context"].to_numpy() == 2
    assert paid.any() and (~paid).any()
    np.testing.assert_array_equal(ep["reward"], np.where(paid, ep["n_frames"] / 100, 0.0))  # 1 per visit of 100 frames
    params = exp.conditions["td"].circuit.specs["VTA"].params
    value, previous, expected = np.zeros(6), -1, []
    for c, r in zip(ep["context"], ep["reward"]):
        da = r if previous < 0 else r + params.discount * value[c] - value[previous]
        if previous >= 0:
            value[previous] += params.rate * da
        expected.append(da)
        previous = c
    np.testing.assert_allclose(ep["da"], expected, rtol=0, atol=1e-12)
    assert (ep["da"] != 0).sum() > len(ep) // 2
