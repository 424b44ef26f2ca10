"""The iCub's own right arm as the look of the simulated iCub world's arm (``SceneParams.arm = "icub"``).

The paper's robot (Luciw et al. 2013, section 4.2, Figure 1) is an iCub that babbles with one
shoulder joint of its outstretched right arm. The scene (:mod:`.icub_scene`) models that arm
with primitive geoms; this module draws it with the iCub's own meshes instead.

The meshes are the iCub's, from the ``icub-models`` package (Istituto Italiano di Tecnologia,
CC BY-SA 4.0; the optional extra ``neurocur[icub]``): the right arm of the model
``iCubGazeboV2_5`` from the upper arm to the hand. Its STL files are exported in one common
assembly frame (the arm outstretched, in millimetres, the URDF scaling them by 0.001), so the
parts fit together as they are; the URDF names each link's mesh and gives its frame, and so the
joint centres used here: the shoulder (the frame of ``r_shoulder_2``, on the shoulder roll
axis), the wrist (``r_wrist_1``, the wrist pitch joint) and the palm (``r_hand_dh_frame``, the
kinematic chain's end-effector frame, in the palm).

Only the look changes. The arm of the scene (:mod:`.icub_scene`) is one rigid body on a vertical
shoulder hinge; its primitive geoms keep their masses, sizes and contacts and become invisible,
and the meshes are drawn in their place as massless, contact-free geoms of the same body. They
are placed along the same arm:

- the upper arm, elbow and forearm as one rigid piece (the elbow straight, the arm
  outstretched as in the paper's Figure 1), from the scene's shoulder hinge to the wrist;
- the wrist and hand turned about the wrist so that the hand lies horizontal along the
  primitive hand, its fingertips at the primitive hand's tip and its axis at the hand's
  height; the palm faces the way the arm sweeps towards the objects (+y of the arm), the
  thumb up;
- one scale for all parts, solved so that both ends meet: 1.03 times the iCub's own size for
  the default scene.

Colours are the scene's own materials (shell, joint, hand), so that only the shapes differ
from the primitive arm.
"""

from __future__ import annotations

import functools
import math
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np

#: the iCub model (``icub-models``) whose right-arm meshes are used
ROBOT = "iCubGazeboV2_5"
#: link -> scene material; the first four move as one piece, the last two turn at the wrist
PROXIMAL = {"r_shoulder_3": "shell", "r_upper_arm": "shell", "r_elbow_1": "joint", "r_forearm": "shell"}
DISTAL = {"r_wrist_1": "joint", "r_hand": "hand"}
#: the extra that installs the meshes
EXTRA = "icub"


def available() -> bool:
    """Whether the ``icub-models`` package (the meshes) is installed."""
    try:
        import icub_models  # noqa: F401
    except ImportError:
        return False
    return True


def _rotation_rpy(rpy) -> np.ndarray:
    """URDF's roll-pitch-yaw: R = Rz(yaw) Ry(pitch) Rx(roll)."""
    r, p, y = rpy
    cx, sx, cy, sy, cz, sz = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    return np.array([[cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx],
                     [sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx],
                     [-sy, cy * sx, cy * cx]])


def _origin(element) -> tuple[np.ndarray, np.ndarray]:
    origin = element.find("origin")
    xyz = [float(v) for v in origin.get("xyz", "0 0 0").split()] if origin is not None else [0.0] * 3
    rpy = [float(v) for v in origin.get("rpy", "0 0 0").split()] if origin is not None else [0.0] * 3
    return _rotation_rpy(rpy), np.array(xyz)


def _stl_vertices(path: Path) -> np.ndarray:
    """The vertices (n, 3) of a binary STL file, in its own units."""
    data = path.read_bytes()
    n = int(np.frombuffer(data, "<u4", count=1, offset=80)[0])
    record = np.dtype([("normal", "<f4", 3), ("v", "<f4", (3, 3)), ("attr", "<u2")])
    return np.frombuffer(data, record, count=n, offset=84)["v"].reshape(-1, 3).astype(np.float64)


@functools.cache
def _model() -> dict:
    """The right arm's meshes and joint centres in the assembly frame (metres), from the URDF.

    A link's visual origin (R, t) places the mesh in the link's frame (p_link = R p_mesh + t),
    so a point q of the link's frame lies at Rᵀ (q - t) in the assembly frame. That the meshes
    share one frame is checked: each link's origin found so must be where its joint, from its
    parent link, puts it (within 2 mm; the URDF agrees to 1 mm).
    """
    import icub_models

    urdf = Path(icub_models.get_model_file(ROBOT))
    package = Path(icub_models.get_models_path()).parent  # share/iCub: "package://iCub/..." below it
    root = ET.parse(urdf).getroot()
    links = {link.get("name"): link for link in root.iter("link")}
    joints = {joint.find("child").get("link"): joint for joint in root.iter("joint")}

    def to_assembly(link: str, q=(0.0, 0.0, 0.0)) -> np.ndarray:
        R, t = _origin(links[link].find("visual"))
        return R.T @ (np.asarray(q, float) - t)

    for name in ("r_shoulder_2", *PROXIMAL, *DISTAL):  # every link's frame where its joint puts it
        joint = joints[name]
        _, offset = _origin(joint)
        gap = np.linalg.norm(to_assembly(joint.find("parent").get("link"), offset) - to_assembly(name))
        if gap > 0.002:
            raise ValueError(f"{urdf}: the mesh of {name} is not in the arm's assembly frame ({gap * 1e3:.1f} mm off)")
    meshes = {}
    for name in (*PROXIMAL, *DISTAL):
        visual = links[name].find("visual")
        mesh = visual.find("geometry/mesh")
        file = package / mesh.get("filename").removeprefix("package://iCub/")
        meshes[name] = (file, float(mesh.get("scale", "1 1 1").split()[0]))
    palm_joint = joints["r_hand_dh_frame"]
    _, palm_in_hand = _origin(palm_joint)
    hand_file, hand_scale = meshes["r_hand"]
    return {
        "meshes": meshes,
        "shoulder": to_assembly("r_shoulder_2"),
        "wrist": to_assembly("r_wrist_1"),
        "palm": to_assembly("r_hand", palm_in_hand),
        "hand_vertices": _stl_vertices(hand_file) * hand_scale,
    }


def _in_plane(v: np.ndarray) -> np.ndarray:
    """``v`` in the arm's plane (the assembly frame's x-z plane), normalised."""
    v = np.array([v[0], 0.0, v[2]])
    return v / np.linalg.norm(v)


def _frame(axis: np.ndarray) -> np.ndarray:
    """Columns: ``axis`` (in the x-z plane), the lateral y axis, and their cross product."""
    y = np.array([0.0, 1.0, 0.0])
    return np.column_stack([axis, y, np.cross(axis, y)])


def placement(tip: float, height: float) -> dict:
    """Where the meshes go in the arm body's frame (origin on the shoulder hinge, x along the arm).

    ``tip``: how far from the hinge axis the primitive hand ends (its fingertip); ``height``:
    the hand's height relative to the shoulder (negative: below it). Returns ``scale`` (of the
    iCub's size) and, per part, the rotation ``R`` and translation ``t`` that take a point
    ``p`` of the assembly frame (metres) to ``t + scale * R @ p``.
    """
    m = _model()
    S, W, P = m["shoulder"], m["wrist"], m["palm"]
    arm_axis, hand_axis = _in_plane(W - S), _in_plane(P - W)
    upper = float(np.linalg.norm((W - S)[[0, 2]]))  # shoulder to wrist
    finger = float(np.max((m["hand_vertices"] - W) @ hand_axis))  # wrist to fingertip, along the hand
    # the wrist lies at (tip - s * finger, height) and s * upper from the hinge: a quadratic in s
    a, b, c = upper**2 - finger**2, 2.0 * tip * finger, -(tip**2 + height**2)
    s = (-b + math.sqrt(b * b - 4 * a * c)) / (2 * a) if a > 0 else -c / b
    wrist = np.array([tip - s * finger, 0.0, height])
    # assembly (axis, y, axis x y) -> arm (axis, -y, ...): the palm (assembly -y) faces the arm's +y,
    # the thumb (against axis x y) points up
    flip = np.diag([1.0, -1.0, -1.0])
    R_arm = _frame(wrist / np.linalg.norm(wrist)) @ flip @ _frame(arm_axis).T
    R_hand = _frame(np.array([1.0, 0.0, 0.0])) @ flip @ _frame(hand_axis).T
    parts = {name: (R_arm, -s * R_arm @ S) for name in PROXIMAL}
    parts.update({name: (R_hand, wrist - s * R_hand @ W) for name in DISTAL})
    return {"scale": s, "parts": parts, "wrist": wrist}


def _vec(v) -> str:
    return " ".join(f"{x:.9g}" for x in v)


def assets(scale: float) -> str:
    """The MJCF ``<mesh>`` assets of the arm's parts, scaled by ``scale`` times the URDF's scale."""
    return "".join(f'\n    <mesh name="icub_{name}" file="{file}" scale="{_vec([scale * unit] * 3)}"/>'
                   for name, (file, unit) in _model()["meshes"].items())


def geoms(tip: float, height: float) -> tuple[str, str]:
    """``(assets, geoms)``: the MJCF of the iCub arm's meshes, placed by :func:`placement`.

    Each geom is visual only: class ``visual`` (no contacts) and ``mass="0"`` (the body's mass
    and inertia are those of the primitive geoms).
    """
    where = placement(tip, height)
    lines = []
    for name, (R, t) in where["parts"].items():
        material = PROXIMAL.get(name) or DISTAL[name]
        lines.append(f'\n      <geom class="visual" type="mesh" mesh="icub_{name}" pos="{_vec(t)}" '
                     f'xyaxes="{_vec(R[:, 0])} {_vec(R[:, 1])}" material="{material}" mass="0"/>')
    return assets(where["scale"]), "".join(lines)
