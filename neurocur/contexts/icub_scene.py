"""The MJCF scene of the simulated iCub experiment (paper section 4.2, Figure 1).

A robot sits at a table with its head fixed; its right arm is outstretched over the
table and turns about a single actuated shoulder joint (a vertical hinge), so the hand
sweeps a horizontal arc a few centimetres above the table top. One object stands on
the table in the arc of the hand:

- ``"topple"``: a tall cup in the middle of the hand's path. The hand passes above the
  height of a fallen cup but below the rim of a standing one, so it tips the cup over
  in the direction the hand moves and then sweeps over it; rolling friction keeps the
  fallen cup where it lies. The outcome is much the same every time.
- ``"roll"``: a ball near the fingertip's end of the path, struck glancingly. Where the
  fingertip meets the ball decides the direction it rolls off in; the ball's placement
  differs from episode to episode by a few millimetres to centimetres along the arm's
  radius (as a hand placing it would), so the direction varies widely.

Contacts: the arm touches only the object (not the table or itself); the arm's geoms
have contact priority, so the hand–object friction is the hand's (a rubbery-ball
friction on the hand would wedge the ball between hand and table).

By default everything is procedural (primitive geoms only, no meshes or textures), so the
scene is small, deterministic and free of asset licences. ``SceneParams.arm = "icub"`` draws
the iCub's own right arm instead (its meshes, from the optional ``icub-models`` package; see
:mod:`.icub_body`): the primitive arm geoms keep their masses, sizes and contacts but are not
drawn, and the meshes are massless and contact-free, so the physics is the same and only the
look changes. Lengths are in metres; the table top is the plane z = 0, the robot faces +x and
its right arm is on the -y side.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..config import ConfigError, ParamSpec, check_params, describe, param, spec_param
from . import icub_body

OBJECTS = ("topple", "roll")
#: the looks of the arm: the scene's own primitive geoms, or the iCub's meshes (same physics)
ARMS = ("primitive", "icub")
#: a point or vector in metres
_XYZ = ParamSpec.sequence(ParamSpec(float), length=3)


@dataclass(frozen=True)
class SceneParams:
    """Geometry and physics of the scene; every field enters the episode-cache key (``arm`` only
    when it is not the default, so that the default's cache keeps its name)."""

    n_states: int = param(20, int, low=2)
    #: shoulder angle (deg, 0 = straight ahead, negative = to the robot's right) of state 0 and state n-1
    angle_first: float = param(-66.0, float)
    angle_last: float = param(24.0, float)
    #: the object's centre sits on the hand's arc at this shoulder angle (deg)
    object_angle: float = param(-29.8, float)
    #: shoulder position (the hinge axis is vertical through it)
    shoulder: tuple[float, float, float] = spec_param((-0.06, -0.17, 0.30), _XYZ)
    #: horizontal reach of the hand's centre from the hinge axis, and the hand's height
    reach: float = param(0.33, float, low=0.0, low_open=True)
    hand_height: float = param(0.082, float, low=0.0, low_open=True)
    hand_radius: float = param(0.02, float, low=0.0, low_open=True)
    #: the cup: radius and height (a fallen cup, 2 * radius high, passes under the hand)
    cup_radius: float = param(0.022, float, low=0.0, low_open=True)
    cup_height: float = param(0.16, float, low=0.0, low_open=True)
    cup_mass: float = param(0.12, float, low=0.0, low_open=True)
    cup_roll_friction: float = param(0.02, float, low=0.0)
    #: the ball: radius, mass, rolling and torsional friction on the table (stops it on the table)
    ball_radius: float = param(0.065, float, low=0.0, low_open=True)
    ball_mass: float = param(0.2, float, low=0.0, low_open=True)
    ball_roll_friction: float = param(0.003, float, low=0.0)
    #: the ball's centre sits this far from the hinge axis, near the fingertip, so that the hand
    #: strikes it glancingly; per episode it is placed within +-ball_jitter of there (radially),
    #: which sends it off in a different direction each time
    ball_reach: float = param(0.40, float, low=0.0, low_open=True)
    ball_jitter: float = param(0.035, float, low=0.0)
    #: shoulder servo: proportional gain (N m / rad) and damping (N m s / rad)
    servo_kp: float = param(60.0, float, low=0.0)
    servo_kv: float = param(4.0, float, low=0.0)
    timestep: float = param(0.002, float, low=0.0, low_open=True)
    #: eye camera pose: position and the point it looks at, vertical field of view (deg)
    camera_pos: tuple[float, float, float] = spec_param((-0.10, -0.03, 0.65), _XYZ)
    camera_target: tuple[float, float, float] = spec_param((0.34, -0.22, 0.0), _XYZ)
    camera_fovy: float = param(48.0, float, low=0.0, low_open=True, high=180.0, high_open=True)
    #: how the arm looks: "primitive" (capsules and spheres) or "icub" (the iCub's own meshes,
    #: from the icub extra); the arm's physics is the same either way
    arm: str = param("primitive", str, choices=ARMS)
    #: the robot's shade against the table: its materials (shell, joint, hand) are the table's colour
    #: plus this fraction of their own colour's difference from it (1: as listed; 0: the table's)
    arm_contrast: float = param(1.0, float, low=0.0, high=1.0)

    def __post_init__(self):
        check_params(self)
        if self.arm == "icub" and not icub_body.available():
            raise ConfigError(type(self).__name__, "arm", f"the icub-models package for arm = 'icub' (install the "
                              f"{icub_body.EXTRA!r} extra: pip install 'neurocur[{icub_body.EXTRA}]')",
                              f"{describe(self.arm)}, and icub-models is not installed")

    def state_angles(self) -> np.ndarray:
        """Shoulder angle (rad) of each of the ``n_states`` quantized joint states."""
        return np.deg2rad(np.linspace(self.angle_first, self.angle_last, self.n_states))

    def object_position(self, obj: str, radial_offset: float = 0.0) -> np.ndarray:
        """Start position (x, y) of the object's centre on the table."""
        a = np.deg2rad(self.object_angle)
        reach = (self.reach if obj == "topple" else self.ball_reach) + radial_offset
        return np.array(self.shoulder[:2]) + reach * np.array([np.cos(a), np.sin(a)])


#: the table's colour, and the robot's materials at full contrast (``arm_contrast = 1``)
TABLE_RGB = (0.42, 0.32, 0.22)
ROBOT_RGB = {"shell": (0.88, 0.88, 0.86), "joint": (0.25, 0.25, 0.28), "hand": (0.55, 0.55, 0.6)}


def _robot_materials(contrast: float) -> str:
    """The robot's materials, each ``TABLE_RGB + contrast * (its colour - TABLE_RGB)``."""
    table = np.array(TABLE_RGB)
    return "".join(f'\n    <material name="{name}" rgba="{_vec(table + contrast * (np.array(rgb) - table))} 1"/>'
                   for name, rgb in ROBOT_RGB.items())


def _vec(v) -> str:
    return " ".join(f"{x:.6g}" for x in v)


def _camera_xyaxes(pos, target) -> str:
    """The camera's x (right) and y (up) axes in world coordinates for a level camera."""
    forward = np.asarray(target, float) - np.asarray(pos, float)
    forward /= np.linalg.norm(forward)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    return _vec(np.concatenate([right, up]))


#: a geom group MuJoCo's renderer does not draw by default (it draws groups 0-2)
NOT_DRAWN = 3


def _robot(p: SceneParams, meshes: str = "") -> str:
    """Torso, fixed head and the right arm on its shoulder hinge (iCub-like proportions).

    ``meshes``: geoms drawn in the arm body after its own (the iCub's arm, :mod:`.icub_body`);
    then the arm's own geoms go to group 3, which the renderer does not draw.
    """
    sx, sy, sz = p.shoulder
    hz = p.hand_height - sz  # hand height relative to the shoulder
    elbow = (0.10, 0.0, 0.5 * hz)
    wrist = (p.reach - 0.045, 0.0, hz)
    hidden = f' group="{NOT_DRAWN}"' if meshes else ""
    return f"""
    <body name="torso" pos="{sx - 0.06:.4g} 0 0">
      <geom class="visual" type="box" size="0.06 0.10 0.16" pos="0 0 0.16" material="shell"/>
      <geom class="visual" type="cylinder" size="0.035 0.03" pos="0 0 0.35" material="joint"/>
      <geom class="visual" type="sphere" size="0.075" pos="0.0 0 0.44" material="shell"/>
      <geom class="visual" type="capsule" size="0.04" fromto="0 0.07 0.30 0 0.12 0.30" material="joint"/>
      <geom class="visual" type="capsule" size="0.04" fromto="0 -0.07 0.30 0 -0.12 0.30" material="joint"/>
    </body>
    <body name="arm" pos="{_vec(p.shoulder)}">
      <joint name="shoulder" type="hinge" axis="0 0 1" damping="0.5" armature="0.01"/>
      <geom class="arm" type="sphere" size="0.035" material="joint"/>
      <geom class="arm" type="capsule" size="0.03" fromto="0 0 0 {_vec(elbow)}" material="shell" mass="0.6"/>
      <geom class="arm" type="sphere" size="0.03" pos="{_vec(elbow)}" material="joint"/>
      <geom class="arm" type="capsule" size="0.025" fromto="{_vec(elbow)} {_vec(wrist)}" material="shell" mass="0.4"/>
      <geom name="hand" class="arm" type="capsule" size="{p.hand_radius:.4g}"
            fromto="{_vec(wrist)} {p.reach + 0.03:.4g} 0 {hz:.4g}" material="hand" mass="0.15"/>
      <geom class="visual" type="box" size="0.02 0.012 0.008" pos="{p.reach - 0.01:.4g} 0.025 {hz + 0.005:.4g}"
            euler="0 0 35" material="hand" mass="0.02"{hidden}/>{meshes}
    </body>"""


def _cup(p: SceneParams, x: float, y: float) -> str:
    """A tall cup; its rolling friction keeps a fallen cup lying where it fell."""
    h, r = p.cup_height, p.cup_radius
    f = p.cup_roll_friction
    return f"""
    <body name="object" pos="{x:.5g} {y:.5g} {h / 2:.5g}">
      <freejoint name="object"/>
      <geom class="object" type="cylinder" size="{r:.4g} {h / 2:.4g}" material="cup" mass="{p.cup_mass:.4g}"
            condim="6" friction="0.6 {f:.4g} {f:.4g}"/>
      <geom class="visual" type="cylinder" size="{r * 0.8:.4g} 0.001" pos="0 0 {h / 2:.4g}" material="inside"/>
      <geom class="visual" type="cylinder" size="{r * 1.04:.4g} 0.006" pos="0 0 {h / 2 - 0.012:.4g}" material="stripe"/>
    </body>"""


def _ball(p: SceneParams, x: float, y: float) -> str:
    """A ball with two painted bands (so that its rolling shows); it rolls freely on the table."""
    r, f = p.ball_radius, p.ball_roll_friction
    return f"""
    <body name="object" pos="{x:.5g} {y:.5g} {r:.5g}">
      <freejoint name="object"/>
      <geom class="object" type="sphere" size="{r:.4g}" material="ball" mass="{p.ball_mass:.4g}"
            condim="6" friction="0.8 {f:.4g} {f:.4g}"/>
      <geom class="visual" type="capsule" size="{r * 0.2:.4g}" fromto="{-r * 0.88:.4g} 0 0 {r * 0.88:.4g} 0 0" material="stripe"/>
      <geom class="visual" type="capsule" size="{r * 0.2:.4g}" fromto="0 {-r * 0.88:.4g} 0 0 {r * 0.88:.4g} 0" material="stripe"/>
    </body>"""


def scene_xml(obj: str, params: SceneParams | None = None, *, height: int = 75, width: int = 100) -> str:
    """The MJCF document of the scene with ``obj`` (``"topple"``: cup, ``"roll"``: ball)."""
    if obj not in OBJECTS:
        raise ValueError(f"obj must be one of {OBJECTS}; got {obj!r}")
    p = params or SceneParams()
    x, y = p.object_position(obj)
    body = _cup(p, x, y) if obj == "topple" else _ball(p, x, y)
    mesh_assets, arm_meshes = "", ""
    if p.arm == "icub":  # the iCub's hand goes where the primitive one is: its tip (the capsule's end
        # and round cap, see _robot) and its height relative to the shoulder
        mesh_assets, arm_meshes = icub_body.geoms(p.reach + 0.03 + p.hand_radius, p.hand_height - p.shoulder[2])
    arm_group = NOT_DRAWN if arm_meshes else 2  # the primitive arm's geoms, drawn unless the iCub's are
    return f"""<mujoco model="icub_{obj}">
  <compiler angle="radian" autolimits="true"/>
  <option timestep="{p.timestep:.6g}" integrator="implicitfast">
    <flag multiccd="enable"/>
  </option>
  <visual>
    <global offwidth="{width}" offheight="{height}"/>
    <quality shadowsize="0" offsamples="0"/>
    <headlight ambient="0.45 0.45 0.45" diffuse="0.5 0.5 0.5" specular="0 0 0"/>
  </visual>
  <asset>
    <material name="table" rgba="{_vec(TABLE_RGB)} 1"/>
    <material name="floor" rgba="0.2 0.2 0.22 1"/>
    <material name="wall" rgba="0.62 0.64 0.66 1"/>{_robot_materials(p.arm_contrast)}
    <material name="cup" rgba="0.95 0.95 0.92 1"/>
    <material name="inside" rgba="0.35 0.3 0.25 1"/>
    <material name="stripe" rgba="0.15 0.3 0.75 1"/>
    <material name="ball" rgba="0.95 0.55 0.1 1"/>{mesh_assets}
  </asset>
  <default>
    <geom solref="0.004 1" solimp="0.95 0.99 0.001"/>
    <default class="visual">
      <geom contype="0" conaffinity="0" group="1"/>
    </default>
    <default class="arm">
      <geom contype="2" conaffinity="0" group="{arm_group}" mass="0.05" priority="1" condim="3" friction="0.4 0.005 0.0001"/>
    </default>
    <default class="object">
      <geom contype="1" conaffinity="3" friction="0.6 0.005 0.0001" group="0"/>
    </default>
  </default>
  <worldbody>
    <light pos="0.3 -0.1 2.0" dir="0 0 -1" diffuse="0.5 0.5 0.5" castshadow="false"/>
    <camera name="eye" pos="{_vec(p.camera_pos)}" xyaxes="{_camera_xyaxes(p.camera_pos, p.camera_target)}" fovy="{p.camera_fovy:.4g}"/>
    <geom name="floor" type="plane" size="3 3 0.1" pos="0 0 -0.72" material="floor" contype="1" conaffinity="1"/>
    <geom name="wall" class="visual" type="box" size="0.02 2 1.2" pos="1.6 0 0" material="wall"/>
    <body name="table">
      <geom name="table_top" type="box" size="0.40 0.55 0.02" pos="0.38 0 -0.02" material="table" contype="1" conaffinity="1"/>
      <geom class="visual" type="box" size="0.025 0.025 0.35" pos="0.03 0.5 -0.37" material="joint"/>
      <geom class="visual" type="box" size="0.025 0.025 0.35" pos="0.73 0.5 -0.37" material="joint"/>
      <geom class="visual" type="box" size="0.025 0.025 0.35" pos="0.03 -0.5 -0.37" material="joint"/>
      <geom class="visual" type="box" size="0.025 0.025 0.35" pos="0.73 -0.5 -0.37" material="joint"/>
    </body>{_robot(p, arm_meshes)}{body}
  </worldbody>
  <actuator>
    <position name="shoulder" joint="shoulder" kp="{p.servo_kp:.6g}" kv="{p.servo_kv:.6g}"/>
  </actuator>
</mujoco>
"""
