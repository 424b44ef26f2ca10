"""VTA: a weighted mixture of an intrinsic dopamine model and the extrinsic reward."""

from __future__ import annotations

from dataclasses import dataclass

from ..config import ParamSpec, check_params, param, spec_param
from .base import register
from .vta import AbsLearningProgressVTA, LearningProgressVTA, NoveltyVTA, VTARole
from .vta_content_novelty import ContentNoveltyVTA
from .vta_surprise import SurpriseVTA

__all__ = ["MixtureVTA", "INTRINSIC"]

#: The intrinsic models a mixture may hold, by type name.
INTRINSIC = {cls.type_name: cls for cls in (LearningProgressVTA, AbsLearningProgressVTA, NoveltyVTA,
                                             ContentNoveltyVTA, SurpriseVTA)}


@dataclass(frozen=True)
class MixtureParams:
    weight: float = param(0.5, float, low=0.0, high=1.0, doc="w, the extrinsic reward's share of DA")
    intrinsic: str = param("vta.learning_progress", str, choices=tuple(INTRINSIC), doc="the intrinsic model's type")
    intrinsic_params: dict = spec_param(
        {}, ParamSpec.table(ParamSpec(float)),
        doc="the intrinsic model's parameters, checked by its own Params (e.g. boredom of the learning-progress "
            "models, scale of novelty, content novelty and surprise); omitted ones keep its defaults")

    def __post_init__(self):
        check_params(self)
        self.intrinsic_model_params()

    def intrinsic_model_params(self):
        """The intrinsic model's Params made from ``intrinsic_params`` (a nested table of that class:
        an error names ``intrinsic_params.<key>`` and the model's own expectation)."""
        spec = ParamSpec.nested(INTRINSIC[self.intrinsic].Params)
        return spec.coerce(self.intrinsic_params, source=type(self).__name__, key="intrinsic_params")


@register("vta.mixture")
class MixtureVTA(VTARole):
    """DA = ``(1 - w) · DA_intrinsic + w · r``: an intrinsic model's dopamine (by default the
    paper's learning progress, section 2.5) mixed with the world's extrinsic reward ``r`` of
    the visit, with weight ``w`` (a trade-off of intrinsic and extrinsic motivation in the
    sense of Barto, Singh & Chentanez 2004, Proc. ICDL). ``w = 0`` is the intrinsic model,
    ``w = 1`` the extrinsic reward alone. ``intrinsic_params`` are the intrinsic model's own
    (``{ boredom = -100.0 }``, ``{ scale = 6.0 }``). The intrinsic model sees the same inputs;
    drugs act on the mixed level only.

    Parameters
    ----------
    name : str
        The region's name in its circuit (default ``"MixtureVTA"``; its intrinsic model is
        ``"<name>.intrinsic"``).
    params : MixtureParams, optional
        ``weight`` (w, in [0, 1], default 0.5), the extrinsic reward's share of DA; ``intrinsic``, the
        intrinsic model's type (a key of ``INTRINSIC``, default ``"vta.learning_progress"``);
        ``intrinsic_params``, that model's own parameters (a table checked by its ``Params``; omitted
        ones keep its defaults).
    **kwargs
        Those parameters as keywords, when ``params`` is not given.
    """

    Params = MixtureParams

    @classmethod
    def reads_reward(cls, params) -> bool:
        """Unless the extrinsic reward's share ``w`` is 0."""
        return params.weight > 0

    def __init__(self, name: str = "", params=None, **kwargs):
        super().__init__(name, params, **kwargs)
        cls = INTRINSIC[self.params.intrinsic]
        self.intrinsic = cls(f"{self.name}.intrinsic", self.params.intrinsic_model_params())

    def bind(self, world) -> None:
        super().bind(world)
        self.intrinsic.bind(world)

    def reset(self, rng) -> None:
        super().reset(rng)
        self.intrinsic.reset(rng)

    def dopamine(self, context, reward_error, familiar, module_learned, reward):
        w = self.params.weight
        return (1.0 - w) * self.intrinsic.dopamine(context, reward_error, familiar, module_learned, reward) + w * reward
