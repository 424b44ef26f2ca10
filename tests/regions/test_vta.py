"""The VTA models (docs/regions.md, "VTA"): each one's defining behaviour on input sequences whose
dopamine is known in closed form, drugs acting on the released level, and the sensory reward."""

from __future__ import annotations

import math

import numpy as np
import pytest
from bound_region import bound, minimal_world

from neurocur.config import ConfigError
from neurocur.contexts.base import Episode
from neurocur.regions import REGIONS
from neurocur.regions.sensory import SensoryWorld
from neurocur.regions.vta import AbsLearningProgressVTA, LearningProgressVTA, NoveltyVTA, VTARole
from neurocur.regions.vta_content_novelty import ContentNoveltyVTA
from neurocur.regions.vta_mixture import INTRINSIC, MixtureVTA
from neurocur.regions.vta_slowness_progress import SlownessProgressVTA
from neurocur.regions.vta_state_progress import StateProgressVTA
from neurocur.regions.vta_surprise import SurpriseVTA
from neurocur.regions.vta_td import TDVTA

NAN = math.nan
VTA_TYPES = [n for n in REGIONS.names() if n.startswith("vta.")]
#: the models that read a ``progress`` input besides the role's ports
PROGRESS_READERS = ("vta.state_progress", "vta.slowness_progress")


def make(cls, n_contexts=3, **params):
    return bound(cls, "VTA", world=minimal_world(n_contexts), **params)


def das(vta, inputs):
    """The released DA of each ``(context, error, familiar, learned, reward[, progress])`` pass; a model
    reads as many of them as it has inputs."""
    n = len(vta.inputs)
    return np.array([vta.step(*x[:n])[0] for x in inputs])


def random_inputs(n=300, n_contexts=3, seed=5):
    """A mixed input stream: errors (some undefined), familiar and storage events, rewards, and HPC's
    same-state progress (some undefined)."""
    rng = np.random.default_rng(seed)
    error = rng.uniform(0.0, 2.0, n)
    error[rng.random(n) < 0.1] = NAN
    familiar = rng.random(n) < 0.15
    learned = ~familiar & (rng.random(n) < 0.03)
    progress = rng.normal(0.0, 0.5, n)
    progress[rng.random(n) < 0.1] = NAN
    return list(zip(rng.integers(n_contexts, size=n).tolist(), error.tolist(), familiar.tolist(), learned.tolist(),
                    rng.normal(0.0, 1.0, n).tolist(), progress.tolist()))


def test_every_vta_type_shares_the_roles_ports_and_releases_dopamine():
    assert {"vta.learning_progress", "vta.abs_learning_progress", "vta.novelty", "vta.content_novelty",
            "vta.surprise", "vta.td", "vta.mixture", "vta.state_progress", "vta.slowness_progress"} <= set(VTA_TYPES)
    role = ["context", "reward_error", "familiar", "module_learned", "reward"]
    for name in VTA_TYPES:
        cls = REGIONS.get(name)
        assert issubclass(cls, VTARole) and cls.modulator == "da"
        extra = ["progress"] if name in PROGRESS_READERS else []  # a model may read more than the role's ports
        assert [s.name for s in cls.inputs] == role + extra
        assert [s.name for s in cls.outputs] == [p.name for p in cls.probes] == ["da"]


class _Affine:
    """A stand-in drug: x' = 3 x - 1."""

    def apply(self, level, rng):
        return 3.0 * level - 1.0


@pytest.mark.parametrize("name", VTA_TYPES)
def test_drugs_act_on_the_released_level(name):
    cls, inputs = REGIONS.get(name), random_inputs()
    plain = das(make(cls), inputs)
    drugged = make(cls)
    drugged.drugs = (_Affine(),)
    released = das(drugged, inputs).tolist()
    assert np.all(np.isfinite(plain))
    if cls is TDVTA:  # V learns from the released level, so the drug changes what follows too
        assert released[0] == 3.0 * plain[0] - 1.0 and not np.allclose(released, 3.0 * plain - 1.0)
    else:
        np.testing.assert_array_equal(released, 3.0 * plain - 1.0)
    assert drugged.record() == (released[-1],)


# ------------------------------------------------------------------ learning progress


def test_learning_progress_signed_and_absolute():
    seq = [(0, 1.0, False, False, 0.0), (0, 0.6, False, False, 0.0), (1, 0.9, False, False, 0.0),
           (0, 0.8, False, False, 0.0), (0, NAN, False, False, 0.0), (0, 0.5, False, False, 0.0),
           (1, 0.7, True, False, 0.0), (1, 0.4, False, True, 0.0), (1, 0.3, False, False, 0.0)]
    # progress since the context's previous defined error; 0 at a first visit or an undefined error;
    # boredom when familiar; the memory cleared after a storage
    signed = [0.0, 0.4, 0.0, -0.2, 0.0, 0.3, -100.0, 0.3, 0.0]
    np.testing.assert_allclose(das(make(LearningProgressVTA), seq), signed, atol=1e-15)
    np.testing.assert_allclose(das(make(AbsLearningProgressVTA), seq), [abs(x) if x != -100 else x for x in signed],
                               atol=1e-15)
    assert das(make(AbsLearningProgressVTA, boredom=-3.0), seq)[6] == -3.0


def test_learning_progress_falls_to_zero_on_noise_while_surprise_stays_at_the_error():
    """On an unlearnable context the error fluctuates about a constant: learning progress sums to
    the first error minus the last (it telescopes), so its mean falls like 1/n, while surprise is
    the error itself and absolute progress the mean absolute change (about 2 sd / sqrt(pi))."""
    rng = np.random.default_rng(1)
    error = 1.0 + 0.1 * rng.standard_normal(2000)
    seq = [(2, e, False, False, 0.0) for e in error]
    lp, surprise, absolute = (das(make(cls), seq) for cls in (LearningProgressVTA, SurpriseVTA,
                                                              AbsLearningProgressVTA))
    assert lp.sum() == pytest.approx(error[0] - error[-1], abs=1e-12)
    assert abs(lp.mean()) < 1e-3
    np.testing.assert_array_equal(surprise, error)
    assert absolute[1:].mean() == pytest.approx(2 * 0.1 / math.sqrt(math.pi), rel=0.05)


@pytest.mark.parametrize("cls", [StateProgressVTA, SlownessProgressVTA])
def test_state_and_slowness_progress_pass_their_progress_input_with_boredom(cls):
    seq = [(0, 1.0, False, False, 0.0, 0.25), (0, 0.6, False, False, 0.0, NAN), (1, 0.9, True, False, 0.0, 0.5),
           (1, NAN, False, True, 3.0, -0.125), (1, 0.3, False, False, 0.0, 0.0625)]
    # progress as it comes, 0 while undefined, boredom when familiar; the error, storage and reward play no part
    assert das(make(cls), seq).tolist() == [0.25, 0.0, -100.0, -0.125, 0.0625]
    assert das(make(cls, boredom=-2.0), seq)[2] == -2.0


# ------------------------------------------------------------------ novelty


def test_content_novelty_falls_with_the_error_not_with_visits():
    learnable = [(0, e, False, False, 0.0) for e in (NAN, 0.8, 0.4, 0.2, 0.1)]
    np.testing.assert_allclose(das(make(ContentNoveltyVTA, scale=2.0), learnable), [2.0, 2.0, 1.0, 0.5, 0.25])
    rng = np.random.default_rng(2)
    noise = [(2, 1.0 + 0.05 * x, False, False, 0.0) for x in rng.standard_normal(400)]
    content, count = das(make(ContentNoveltyVTA), noise), das(make(NoveltyVTA), noise)
    np.testing.assert_allclose(count, 1.0 / np.sqrt(np.arange(1, 401)))
    assert content[-100:].mean() > 0.9 and count[-100:].mean() < 0.06
    # a familiar episode (its content stored) is not novel; a storage forgets the first errors
    vta = make(ContentNoveltyVTA)
    assert das(vta, [(1, 0.5, False, False, 0.0), (1, 0.25, False, True, 0.0), (1, 0.2, True, False, 0.0),
                     (1, 0.4, False, False, 0.0), (1, 0.1, False, False, 0.0)]).tolist() == [1.0, 0.5, 0.0, 1.0, 0.25]


def test_content_novelty_is_capped_at_one_and_zero_for_a_perfect_first_fit():
    assert das(make(ContentNoveltyVTA), [(0, 0.5, False, False, 0.0), (0, 0.9, False, False, 0.0)]).tolist() == [1, 1]
    assert das(make(ContentNoveltyVTA), [(0, 0.0, False, False, 0.0), (0, 0.3, False, False, 0.0)]).tolist() == [1, 0]


def test_surprise_is_zero_when_familiar_or_undefined():
    seq = [(0, 0.7, False, False, 5.0), (0, NAN, False, False, 0.0), (0, 0.7, True, False, 0.0)]
    assert das(make(SurpriseVTA, scale=2.0), seq).tolist() == [1.4, 0.0, 0.0]


# ------------------------------------------------------------------ temporal difference


@pytest.mark.parametrize("rate, discount", [(0.1, 0.9), (0.5, 0.0), (1.0, 0.5)])
def test_td_on_one_rewarded_context_follows_the_closed_form(rate, discount):
    """One context, reward r every visit: V_n = r/(1-g) (1 - (1 - a(1-g))^n) after n updates,
    and the n-th prediction error (n >= 1) is r (1 - a(1-g))^(n-1)."""
    r, n = 2.0, 400
    vta = make(TDVTA, 1, rate=rate, discount=discount)
    da = das(vta, [(0, NAN, False, False, r)] * (n + 1))
    k = 1.0 - rate * (1.0 - discount)
    assert da[0] == r  # no previous state
    np.testing.assert_allclose(da[1:], r * k ** np.arange(n), rtol=1e-12, atol=1e-13)
    assert vta.value[0] == pytest.approx(r / (1 - discount) * (1 - k**n), rel=1e-12)


def test_td_on_a_reward_cycle_converges_to_the_bellman_values():
    """Contexts visited 0 -> 1 -> 2 -> 0 ..., each visit paying r(c): V solves V(c) = r(c+1) + g V(c+1)."""
    rewards, g = np.array([1.0, 0.0, 2.0]), 0.8
    vta = make(TDVTA, 3, rate=0.3, discount=g)
    cycle = [(c, NAN, False, False, rewards[c]) for c in range(3)]
    da = das(vta, cycle * 1000)
    nxt = np.roll(np.eye(3), 1, axis=1)  # c -> c + 1
    expected = np.linalg.solve(np.eye(3) - g * nxt, nxt @ rewards)
    np.testing.assert_allclose(vta.value, expected, rtol=1e-9)
    assert np.abs(da[-30:]).max() < 1e-9 and abs(da[3]) > 0.1


def test_td_ignores_the_intrinsic_inputs():
    inputs = random_inputs()
    silent = [(c, e, f, m, 0.0) for c, e, f, m, *_ in inputs]
    assert not das(make(TDVTA), silent).any()
    same = [(c, 0.5, False, False, r) for c, _, _, _, r, _ in inputs]
    np.testing.assert_array_equal(das(make(TDVTA), inputs), das(make(TDVTA), same))


# ------------------------------------------------------------------ mixture


@pytest.mark.parametrize("intrinsic", list(INTRINSIC))
def test_mixture_at_the_ends_equals_its_parts(intrinsic):
    inputs, cls = random_inputs(), INTRINSIC[intrinsic]
    alone = das(make(cls), inputs)
    reward = np.array([x[4] for x in inputs])
    np.testing.assert_array_equal(das(make(MixtureVTA, weight=0.0, intrinsic=intrinsic), inputs), alone)
    np.testing.assert_array_equal(das(make(MixtureVTA, weight=1.0, intrinsic=intrinsic), inputs), reward)
    np.testing.assert_allclose(das(make(MixtureVTA, weight=0.25, intrinsic=intrinsic), inputs),
                               0.75 * alone + 0.25 * reward, rtol=1e-12, atol=1e-12)


def test_mixture_passes_the_intrinsic_models_parameters():
    seq = [(0, 0.3, True, False, 4.0)]
    assert das(make(MixtureVTA, weight=0.5, intrinsic_params={"boredom": -10.0}), seq).tolist() == [-3.0]
    novelty = make(MixtureVTA, weight=0.5, intrinsic="vta.novelty", intrinsic_params={"scale": 6})
    assert das(novelty, seq).tolist() == [5.0]
    assert novelty.intrinsic.params == NoveltyVTA.Params(scale=6.0)


# ------------------------------------------------------------------ sensory: the extrinsic reward


class _PayingWorld:
    """Two contexts of 4 frames; each visit pays 10 * context + the visit's number."""

    n_contexts = 2

    def __init__(self):
        self.visits = 0

    def reset(self, *, seed, context):
        self.visits = 0
        return self._episode(context), {}

    def step(self, context):
        return self._episode(context), 0.0, False, False, {}

    def _episode(self, context):
        self.visits += 1
        return Episode(frames=np.zeros((4, 2)), states=np.arange(4), context=context, reward=10.0 * context + self.visits)


def test_sensory_emits_and_records_the_reward_summed_over_a_block():
    s = SensoryWorld("sensory", episodes_on_engage=3, initial_context=1)
    s.bind(_PayingWorld())
    s.reset(np.random.default_rng(0))
    assert s.step(None)[1:] == (1, 11.0) and s.record() == (1, 4, 11.0)
    block, c, reward = s.step(1)  # staying: visits 2, 3 and 4 of context 1, one block
    assert (c, reward, len(block.frames), block.reward) == (1, 3 * 10.0 + 2 + 3 + 4, 12, 39.0)
    assert s.record() == (1, 12, 39.0)
    assert s.step(0)[1:] == (0, 5.0) and s.record() == (0, 4, 5.0)


def test_mixture_checks_the_intrinsic_parameters_by_the_models_own_params():
    """``intrinsic_params`` is a nested table of the chosen model's Params: nothing re-declared in the mixture."""
    with pytest.raises(ConfigError, match=r"^MixtureParams: key 'intrinsic_params.scale': expected a parameter of "
                                          r"LearningProgressParams \(boredom\), got an unknown parameter$"):
        MixtureVTA.Params(intrinsic_params={"scale": 2.0})
    with pytest.raises(ConfigError, match=r"^MixtureParams: key 'intrinsic_params.scale': expected a number > 0"):
        MixtureVTA.Params(intrinsic="vta.surprise", intrinsic_params={"scale": 0.0})
    params = MixtureVTA.Params(intrinsic="vta.content_novelty", intrinsic_params={"scale": 3})
    assert params.intrinsic_model_params() == INTRINSIC["vta.content_novelty"].Params(scale=3.0)
    assert MixtureVTA.Params().intrinsic_model_params() == INTRINSIC["vta.learning_progress"].Params()
