"""Drawing refsim's things into a viser scene, for the live viewer and the
replays alike: the world cube, the bodies, their boxes, contact triangles
and wall-hit arrows, placed from recorded frames.

Each function takes viser's scene API (``server.scene``) and a node name;
names under one prefix (``/run0/...``) form a group that the scene tree
shows and hides together. Colours are RGB tuples of 0-255.
"""

from __future__ import annotations

import numpy as np

from refsim.viewer.overlays import box_edges, cube_edges, triangle_soup
from refsim.viewer.server import wxyz

#: Body colours, one per body (cycled): distinguishable on white and in print
#: (Okabe and Ito's colour-blind-safe palette, without its black and yellow).
PALETTE = ((0, 114, 178), (213, 94, 0), (0, 158, 115), (204, 121, 167), (86, 180, 233),
           (230, 159, 0))

CUBE_COLOR = (60, 60, 60)
BOX_COLOR = (0, 160, 80)
CONTACT_COLOR = (220, 20, 60)
NORMAL_COLOR = (30, 90, 220)
IMPULSE_COLOR = (240, 120, 0)

#: Contacting triangles are drawn this fraction of the body's size off its faces.
CONTACT_LIFT = 0.003

#: Lines drawn in screen pixels, so that they stay visible at any zoom.
CUBE_LINE_PX = 2.0
BOX_LINE_PX = 1.5

#: Length of a drawn wall normal, as a fraction of the cube's half size.
NORMAL_LENGTH = 0.15

#: A wall impulse J (N s) of a body of mass m is drawn as the velocity change
#: J / m times this many seconds (so 10 m/s of change is 1 m long).
IMPULSE_SECONDS = 0.1


#: The camera's vertical field of view (degrees): narrower than viser's 75,
#: for less distortion of the cube's edges.
FOV_DEGREES = 45.0

#: Where the camera looks from: up and to the right of the front (a unit
#: direction is taken of it), the cube's floor in view.
VIEW_DIRECTION = (0.45, 0.5, 1.0)

#: Runs side by side are seen nearly from the front, so that heights compare.
FRONT_DIRECTION = (0.12, 0.3, 1.0)

#: Distance beyond the fit, for the GUI panel beside the view.
CAMERA_MARGIN = 1.1

#: A box this many times wider than high is fitted to the window's width.
WIDE = 1.5

#: The live viewer's control panel floats over the right of the window, a
#: replay's settings panel over its left (each about a quarter of a laptop's
#: width): the camera is panned so that the scene sits this fraction of the
#: view's width off centre, away from the panel, in the clear part.
PANEL_PAN = 0.12


def place_camera(camera, width: float, height: float, depth: float | None = None,
                 center=(0.0, 0.0, 0.0), direction=VIEW_DIRECTION,
                 margin: float = CAMERA_MARGIN, pan: float = 0.0) -> None:
    """Point viser's camera (``server.initial_camera``) at a box of
    ``width`` (x), ``height`` (y) and ``depth`` (z, default the height)
    about ``center``, from VIEW_DIRECTION, far enough that the box's
    bounding sphere fits the view of a window about 1.6 times as wide as high
    (a sphere, since the view is oblique), with a margin for the panels.
    ``pan``: move the camera and its target to the right by this fraction of
    the view's width, so that the box appears that much left of centre
    (:data:`PANEL_PAN` keeps it clear of a panel on the right)."""
    import math

    depth = height if depth is None else depth
    half_v = math.radians(FOV_DEGREES) / 2.0
    half_h = math.atan(math.tan(half_v) * 1.6)
    radius = 0.5 * math.sqrt(width * width + height * height + depth * depth)
    # a wide box (runs side by side) fills the window's width; a cube its height
    half = half_h if width > WIDE * height else half_v
    d = margin * radius / math.sin(half)
    direction = np.asarray(direction, dtype=np.float64)
    direction /= np.sqrt(direction @ direction)
    # the screen's right: the view direction (-direction) crossed with up
    right = np.array([direction[2], 0.0, -direction[0]])
    right /= np.sqrt(right @ right)
    target = np.asarray(center, dtype=np.float64) + pan * 2.0 * d * math.tan(half_h) * right
    camera.fov = math.radians(FOV_DEGREES)
    camera.look_at = tuple(target)
    camera.position = tuple(target + d * direction)
    camera.up = (0.0, 1.0, 0.0)


def color(i: int) -> tuple[int, int, int]:
    return PALETTE[i % len(PALETTE)]


def add_cube(scene, name: str, half_size: float, offset=(0.0, 0.0, 0.0),
             rgb=CUBE_COLOR):
    """The world cube's 12 edges."""
    return scene.add_line_segments(name, cube_edges(half_size, offset), rgb,
                                   thickness=CUBE_LINE_PX, thickness_units="screen")


def add_body(scene, name: str, mesh, rgb, *, opacity: float | None = None):
    """One body's mesh, in body space (its pose is set per frame)."""
    return scene.add_mesh_simple(name, mesh.vertices, mesh.faces, color=rgb,
                                 flat_shading=True, opacity=opacity,
                                 side="double" if opacity is not None else "front")


def pose_args(rotation, position, offset=(0.0, 0.0, 0.0)) -> dict:
    """viser's ``wxyz`` and ``position`` of a body at a recorded pose, moved by ``offset``."""
    return {"wxyz": wxyz(rotation), "position": np.asarray(position) + np.asarray(offset)}


def set_pose(handle, rotation, position, offset=(0.0, 0.0, 0.0)) -> None:
    q = pose_args(rotation, position, offset)
    handle.wxyz = q["wxyz"]
    handle.position = q["position"]


def boxes_segments(boxes: np.ndarray, offset=(0.0, 0.0, 0.0)) -> np.ndarray:
    """(B * 12, 2, 3) edges of the boxes (B, 2, 3) of one frame."""
    return (box_edges(boxes[:, 0], boxes[:, 1]) + np.asarray(offset)).reshape(-1, 2, 3)


def add_boxes(scene, name: str, boxes: np.ndarray, offset=(0.0, 0.0, 0.0), *,
              visible: bool = True):
    return scene.add_line_segments(name, boxes_segments(boxes, offset), BOX_COLOR,
                                   thickness=BOX_LINE_PX, thickness_units="screen",
                                   visible=visible)


def contact_mesh(meshes, rotations, positions, found) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (3k, 3) and faces (k, 3) of the contacting triangles ``found``
    (a list of :class:`~refsim.viewer.overlays.TrianglePairs`), both sides of
    each pair, for one mesh node drawn over the bodies."""
    soups = []
    for hit in found:
        for body, column in ((hit.a, 0), (hit.b, 1)):
            faces = np.unique(hit.pairs[:, column])
            soup = triangle_soup(meshes[body], rotations[body], positions[body], faces)
            # lifted off the body's own faces along their outward normals,
            # so that the two do not fight for the same pixels
            n = np.cross(soup[:, 1] - soup[:, 0], soup[:, 2] - soup[:, 0])
            n /= np.maximum(np.sqrt((n * n).sum(axis=1, keepdims=True)), 1e-300)
            extent = float(np.ptp(meshes[body].vertices, axis=0).max())
            soups.append(soup + CONTACT_LIFT * extent * n[:, None, :])
    if not soups:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    corners = np.concatenate(soups).reshape(-1, 3)
    return corners, np.arange(len(corners)).reshape(-1, 3)


#: An arrow's head: this fraction of its length, barbs this fraction wide.
HEAD_LENGTH = 0.25
HEAD_WIDTH = 0.1
ARROW_LINE_PX = 3.0


def arrow_segments(arrows: np.ndarray) -> np.ndarray:
    """(5 k, 2, 3) line segments drawing k arrows (k, 2, 3) ``[start, end]``:
    the shaft and four barbs of the head.

    (viser's own ``add_arrows`` is not used: in viser 1.1.1 under SwiftShader
    its arrows vanish from a scene that holds a mesh.)
    """
    arrows = np.asarray(arrows, dtype=np.float64).reshape(-1, 2, 3)
    segments = []
    for start, end in arrows:
        d = end - start
        length = float(np.sqrt(d @ d))
        if length == 0.0:
            continue
        d = d / length
        # two unit vectors across the arrow: any vector not along d, crossed
        helper = np.eye(3)[int(np.argmin(np.abs(d)))]
        u = np.cross(d, helper)
        u /= np.sqrt(u @ u)
        w = np.cross(d, u)
        base = end - HEAD_LENGTH * length * d
        segments.append((start, end))
        for side in (u, -u, w, -w):
            segments.append((end, base + HEAD_WIDTH * length * side))
    return np.array(segments, dtype=np.float64).reshape(-1, 2, 3)


def add_arrows(scene, name: str, arrows: np.ndarray, rgb):
    """Arrows (k, 2, 3) ``[start, end]`` as lines (see :func:`arrow_segments`)."""
    return scene.add_line_segments(name, arrow_segments(arrows), rgb,
                                   thickness=ARROW_LINE_PX, thickness_units="screen")


def hit_arrows(hits, masses, half_size: float) -> tuple[np.ndarray, np.ndarray]:
    """(k, 2, 3) normal arrows and (k, 2, 3) impulse arrows of wall hits, each
    ending at the contact point, as the wall pushes: they start outside the
    cube, where the body does not hide them (lengths: NORMAL_LENGTH,
    IMPULSE_SECONDS)."""
    normals = np.array([[h.point - NORMAL_LENGTH * half_size * h.normal, h.point]
                        for h in hits]).reshape(-1, 2, 3)
    impulses = np.array([[h.point - IMPULSE_SECONDS * h.impulse / masses[h.body], h.point]
                         for h in hits]).reshape(-1, 2, 3)
    return normals, impulses
