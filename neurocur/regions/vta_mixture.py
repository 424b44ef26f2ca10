"""VTA: a weighted mixture of an intrinsic dopamine model and the extrinsic reward."""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from ..config import ConfigError, check_params, describe, param
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
    boredom: float = param(-100.0, float, doc="the intrinsic model's boredom (learning progress models)")
    scale: float = param(1.0, float, low=0.0, low_open=True,
                         doc="the intrinsic model's scale (novelty, content novelty, surprise)")

    def __post_init__(self):
        check_params(self)
        self.intrinsic_model_params()

    def intrinsic_model_params(self):
        """The intrinsic model's parameters: those of this mixture's that its Params declares.

        A parameter the intrinsic model lacks must keep its default, so that no setting is ignored.
        """
        cls = INTRINSIC[self.intrinsic].Params
        own = {f.name for f in dataclasses.fields(cls)}
        for name in ("boredom", "scale"):
            default = next(f.default for f in dataclasses.fields(self) if f.name == name)
            if name not in own and getattr(self, name) != default:
                raise ConfigError(type(self).__name__, name,
                                  f"its default {default:g}: {self.intrinsic} has no {name} (its parameters: "
                                  f"{', '.join(sorted(own))})", describe(getattr(self, name)))
        return cls(**{name: getattr(self, name) for name in own})


@register("vta.mixture")
class MixtureVTA(VTARole):
    """DA = ``(1 - w) · DA_intrinsic + w · r``: an intrinsic model's dopamine (by default the
    paper's learning progress, section 2.5) mixed with the world's extrinsic reward ``r`` of
    the visit, with weight ``w`` (a trade-off of intrinsic and extrinsic motivation in the
    sense of Barto, Singh & Chentanez 2004, Proc. ICDL). ``w = 0`` is the intrinsic model,
    ``w = 1`` the extrinsic reward alone. ``boredom`` and ``scale`` go to the intrinsic model
    (each only to a model that has it). The intrinsic model sees the same inputs; drugs act
    on the mixed level only."""

    Params = MixtureParams

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
