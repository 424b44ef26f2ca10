"""Figure 5 (section 4.1.5): a learned slow feature is invariant to the other source dimension."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from matplotlib.image import imread

from neurocur.analysis.figures.invariance import fig_invariance
from neurocur.cli import main
from neurocur.config import ConfigError
from neurocur.contexts.synthetic import SyntheticWorld, mix_frames
from neurocur.experiments.invariance import invariance_demo, load_invariance
from neurocur.learn.incsfa import IncSFA

INVARIANCE = Path(__file__).resolve().parents[2] / "neurocur" / "experiments_data" / "invariance.toml"


@pytest.fixture(scope="module")
def demo():
    return load_invariance(INVARIANCE).run()


def test_learned_feature_is_invariant_under_global_normalisation(demo):
    spec = load_invariance(INVARIANCE)
    assert (spec.source, spec.normalise, spec.incsfa["mca_rate"]) == ("S-A", "global", 0.05)
    # the swap changes the observations a lot ...
    assert abs(np.corrcoef(demo.noisy_source[:, 1], demo.source[:, 1])[0, 1]) < 0.1
    np.testing.assert_array_equal(demo.noisy_source[:, 0], demo.source[:, 0])
    change = np.linalg.norm(demo.noisy_frames - demo.frames) / np.linalg.norm(demo.frames - demo.frames.mean(0))
    assert change > 0.3
    # ... but not the slowest feature, which extracts the slow source dimension
    assert demo.quality >= 0.99
    assert demo.corr >= 0.99


def test_a_feature_learned_on_another_source_is_not_invariant():
    """IncSFA trained on S-B's frames, then shown S-A's frames before and after the swap."""
    world = SyntheticWorld(["S-A", "S-B"], clock_offsets="zero")
    world.reset(seed=3)
    sfa = IncSFA(2, 3, random_state=3)
    for epoch in range(30):
        sfa.partial_fit(world.context_frames(1), continues=epoch > 0)
    source = world.source_signal("S-A")
    noisy = source.copy()
    noisy[:, 1] = world.np_random.uniform(-1.0, 1.0, len(noisy))
    noisy_frames, _ = mix_frames(noisy, world.mixing("S-A"), "global", limits=world.normalisation_limits("S-A"))
    before = sfa.transform(world.context_frames(0))[:, 0]
    after = sfa.transform(noisy_frames)[:, 0]
    assert abs(np.corrcoef(before, after)[0, 1]) < 0.9


def test_the_unlearnable_source_gives_no_invariant_feature():
    """S-D has no unique slowest direction: its first feature mixes both dimensions."""
    result = invariance_demo("S-D", epochs=30, seed=2013)
    assert result.corr < 0.9


def test_image_normalisation_is_only_approximately_invariant():
    result = invariance_demo("S-A", epochs=30, seed=2013, normalise="image")
    assert 0.5 < result.corr < 0.99


def test_figure_panels(demo):
    fig = fig_invariance(demo)
    titles = [ax.get_title(loc="left") for ax in fig.axes]
    assert [t[0] for t in titles] == ["A", "B", "C", "D", "E", "F"]
    panel = dict(zip("ABCDEF", fig.axes))
    np.testing.assert_array_equal(panel["C"].lines[0].get_ydata(), demo.output)
    np.testing.assert_array_equal(panel["F"].lines[-1].get_ydata(), demo.noisy_output)
    np.testing.assert_array_equal(panel["D"].lines[1].get_ydata(), demo.noisy_source[:, 1])
    shown = panel["B"].images[0].get_array()
    assert shown.shape == (20, 4 * 21 - 1)
    np.testing.assert_array_equal(shown[:, :20], demo.frames[200].reshape(20, 20))
    with pytest.raises(ValueError, match="frame_shape"):
        fig_invariance(demo, frame_shape=(10, 10))


def test_cli_writes_figure_and_json(tmp_path, capsys):
    out = tmp_path / "fig5"
    assert main(["invariance", str(INVARIANCE), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "corr = " in printed and str(out / "invariance.png") in printed
    result = json.loads((out / "invariance.json").read_text())
    assert result["source"] == "S-A" and result["epochs"] == 30 and result["incsfa"]["n_pca"] == 3
    assert result["corr"] >= 0.99 and result["quality"] >= 0.99
    image = imread(out / "invariance.png")
    assert image.ndim == 3 and image.shape[0] > 300 and image.shape[1] > 600


@pytest.mark.parametrize("text, key", [
    ('source = "S-X"', "source"),
    ('source = "S-A"\nepochs = 0', "epochs"),
    ('source = "S-A"\nnormalise = "pixel"', "normalise"),
    ('source = "S-A"\n[incsfa]\nmca_rate = 0.9', "incsfa.mca_rate"),
    ('source = "S-A"\n[incsfa]\nrandom_state = 1', "incsfa.random_state"),
    ('source = "S-A"\n[incsfa]\nn_components = 3\nn_pca = 2', "incsfa"),
    ('source = "S-A"\nsteps = 3', "steps"),
])
def test_bad_files_name_the_key(tmp_path, text, key, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(text + "\n")
    with pytest.raises(ConfigError) as info:
        load_invariance(path)
    assert info.value.key == key and str(path) in str(info.value)
    assert main(["invariance", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert f"key '{key}'" in err and err.count("\n") == 1
    assert not (tmp_path / "out").exists()


def test_invariance_demo_feature_ignores_the_other_dimension():
    demo = invariance_demo("S-A", epochs=10, seed=0)
    assert demo.quality > 0.99  # the slowest feature is the slow source dimension
    assert not np.allclose(demo.frames, demo.noisy_frames)  # the images change ...
    assert demo.corr >= 0.95  # ... the first feature's output does not
    # per-image normalisation makes the frames non-linear in the source: invariance is only approximate
    image = invariance_demo("S-A", epochs=10, seed=0, normalise="image")
    assert image.corr < demo.corr
