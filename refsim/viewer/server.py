"""Starting viser: the optional import, the port, and the conventions.

Everything viser-specific that both the live viewer and the replay writer
need, in one place: :func:`require_viser` (one clear error when the
``viewer`` extra is missing), :func:`start_server` (bound to 127.0.0.1 unless
told otherwise, refusing a port in use instead of moving to the next one as
viser does), and :func:`wxyz` (refsim's orientation matrix as viser's
quaternion).

Conventions converted here: refsim's orientation is a 3x3 matrix whose
columns are the body's axes in world space, so a body-space vertex ``p``
sits at ``R p + x``; viser's node pose is a quaternion ``(w, x, y, z)`` of
the same rotation (local to parent) and a position. y is up in both: the
server is told so (viser's default is +z).
"""

from __future__ import annotations

import contextlib
import errno
import io
import socket

import numpy as np

from refsim.errors import RefsimError

#: What ``pip`` installs for the viewer (pyproject.toml's ``viewer`` extra).
INSTALL_HINT = "pip install 'refsim[viewer]'"

#: The address the viewer binds to unless told otherwise: this machine only.
#: (viser's own default, 0.0.0.0, would serve the page to the whole network.)
LOCAL_HOST = "127.0.0.1"


#: Intensity of the ambient light added to viser's default lights (a display choice).
AMBIENT_LIGHT = 1.5


class ViewerUnavailable(RefsimError, ImportError):
    """viser, the viewer's one dependency, is not installed."""


def require_viser():
    """The ``viser`` module, or :class:`ViewerUnavailable` saying what to install."""
    try:
        import viser
    except ImportError:
        raise ViewerUnavailable(f"the viewer needs viser, which is not installed: "
                                f"{INSTALL_HINT}") from None
    return viser


def check_port(port) -> int:
    """``port`` as an int in 0..65535 (0: any free port), else RefsimError."""
    if isinstance(port, bool) or not isinstance(port, int) or not 0 <= port <= 65535:
        raise RefsimError(f"port must be a whole number from 0 to 65535, got {port!r}")
    return port


def port_in_use(host: str, port: int) -> bool:
    """Whether binding ``(host, port)`` fails because something listens there.

    The probe sets SO_REUSEADDR as servers do, so a port whose last
    connection lingers in TIME_WAIT counts as free (the server can take it).
    """
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind((host, port))
        except OSError as exc:
            if exc.errno == errno.EADDRINUSE:
                return True
            raise RefsimError(f"cannot listen on {host}:{port}: "
                              f"{exc.strerror or exc}") from None
    return False


def start_server(host: str = LOCAL_HOST, port: int = 0, *, label: str | None = None):
    """A running ``viser.ViserServer`` on ``host:port``, y up.

    ``port=0`` takes any free port (``server.get_port()`` says which).
    Raises RefsimError ``port N is in use`` when another program listens on
    a nonzero ``port`` (viser itself would silently take the next free one),
    and :class:`ViewerUnavailable` without viser.
    """
    viser = require_viser()
    port = check_port(port)
    if port and port_in_use(host, port):
        raise RefsimError(f"port {port} is in use")
    # viser prints a banner with the address; the command line prints its own line.
    with contextlib.redirect_stdout(io.StringIO()):
        server = viser.ViserServer(host=host, port=port, label=label, verbose=False)
    if port and server.get_port() != port:       # taken between the probe and the bind
        stop_server(server)
        raise RefsimError(f"port {port} is in use")
    server.scene.set_up_direction("+y")
    # Plain lights, no shadows and no environment map: viser's default image-
    # based lighting costs seconds of shader work per page in a software
    # renderer (SwiftShader, headless Chromium, a machine without a GPU),
    # stalling the page; refsim's flat-shaded bodies need none of it.
    server.scene.configure_environment_map(hdri=None)
    server.scene.configure_default_lights(enabled=True, cast_shadow=False)
    # what the environment map gave: light on the faces turned away
    server.scene.add_light_ambient("/lights/ambient", intensity=AMBIENT_LIGHT)
    return server


def stop_server(server) -> None:
    """Stop ``server`` and its threads, quietly."""
    with contextlib.redirect_stdout(io.StringIO()):
        server.stop()


def url(server) -> str:
    """The page's address, e.g. ``http://127.0.0.1:8080``."""
    host = server.get_host()
    host = "localhost" if host in ("0.0.0.0", "::") else host
    return f"http://{host}:{server.get_port()}"


def wxyz(rotation: np.ndarray) -> np.ndarray:
    """Quaternions ``(..., 4)`` as ``(w, x, y, z)`` of rotations ``(..., 3, 3)``.

    The branch on the largest of ``w, x, y, z`` (Shepperd's method: S. W.
    Shepperd, "Quaternion from rotation matrix", J. Guidance and Control
    1(3), 1978) keeps the square root away from zero. A rotation and its
    quaternion's negative are the same; the sign is fixed by the branch.
    """
    R = np.asarray(rotation, dtype=np.float64)
    m00, m11, m22 = R[..., 0, 0], R[..., 1, 1], R[..., 2, 2]
    trace = m00 + m11 + m22
    candidates = np.stack([trace, m00, m11, m22], axis=-1)
    branch = np.argmax(candidates, axis=-1)
    q = np.empty(R.shape[:-2] + (4,))
    # 4 w^2 = 1 + trace, 4 x^2 = 1 + m00 - m11 - m22, and so on.
    s = np.sqrt(np.maximum(1.0 + 2.0 * candidates.max(axis=-1) - trace, 1e-300)) * 2.0
    d21, d02, d10 = R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0], \
        R[..., 1, 0] - R[..., 0, 1]
    s21, s02, s10 = R[..., 2, 1] + R[..., 1, 2], R[..., 0, 2] + R[..., 2, 0], \
        R[..., 1, 0] + R[..., 0, 1]
    rows = {
        0: (0.25 * s, d21 / s, d02 / s, d10 / s),
        1: (d21 / s, 0.25 * s, s10 / s, s02 / s),
        2: (d02 / s, s10 / s, 0.25 * s, s21 / s),
        3: (d10 / s, s02 / s, s21 / s, 0.25 * s),
    }
    for b, row in rows.items():
        mask = branch == b
        q[mask] = np.stack(row, axis=-1)[mask]
    return q
