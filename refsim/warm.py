"""Compiles the kernel families that start tiered, in a process of their own.

A default call runs the readable kernels while numba's cache lacks its
family's machine code (:class:`refsim.kernels.Tier`). A long command
(``refsim conform``) would then spend
up to one compile's time per family on readable calls before compiling in
the foreground. Instead it starts this module in a second process
(:func:`start_in_background`): the compile runs beside the readable calls,
on another core where there is one, and writes numba's disk cache; each
tier of the command's process finds its family there on its next call
(:func:`refsim.kernels.compiled_here` reads the cache's index) and loads
it. The results are the same bits whichever kernel a call took.

numba writes each cache file to a temporary name and renames it, so a
command that ends before the compile does leaves no half-written entry;
the background process goes on to finish the cache for the next run.

``python -m refsim.warm`` compiles every cold family and prints one line
per family; ``python -m refsim.warm NAME`` compiles the family ``NAME``
(a key of :data:`COMPILERS`). :func:`compile_side_by_side` compiles the
cold families in processes side by side.
"""

from __future__ import annotations

import subprocess
import sys

import numpy as np

from refsim.kernels import numba_usable


def tiers():
    """The tiered families, by the modules that hold them."""
    from refsim.collision.bodies import EXACT_QUERY
    from refsim.dynamics.start import LOOP
    from refsim.particles.system import FUSED_STEPS

    return (EXACT_QUERY, LOOP, FUSED_STEPS)


def cold_tiers() -> list:
    """The families a default call would now run readable (numba usable,
    the tiered start on, their machine code not in the cache)."""
    return [tier for tier in tiers() if tier.readable_first()]


def _compile_exact_query() -> None:
    from refsim.collision.bodies import bodies_collide, intersecting_pairs
    from refsim.models.mesh import Mesh

    tetra = Mesh([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]],
                 [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    near = (np.eye(3), np.array([0.5, 0.0, 0.0]))
    here = (np.eye(3), np.zeros(3))
    intersecting_pairs(tetra, here, tetra, near, kernel="compiled")
    bodies_collide(tetra, here, tetra, near, kernel="compiled")


def _compile_loop() -> None:
    from refsim.dynamics.simulate import simulate
    from refsim.scenes.loader import load_scene

    scene = load_scene("spinning-cube.toml")
    simulate(scene, duration=10 * scene.integration.step, kernel="compiled")


def _compile_particles() -> None:
    from refsim.particles.system import ParticleSystem
    from refsim.scenes.loader import load_scene

    config = load_scene("particles.toml").particles
    assert config is not None                 # the bundled scene has particles
    ParticleSystem(config, kernel="compiled").run(1)


#: What compiles each family, by the tier's name.
COMPILERS = {"exact collision query": _compile_exact_query,
             "simulation loop": _compile_loop,
             "fused particle steps": _compile_particles}


def warm(stream=sys.stdout) -> list[str]:
    """Compiles every cold family (one line on ``stream`` each); returns
    their names."""
    names = [tier.name for tier in cold_tiers()]
    for name in names:
        COMPILERS[name]()
        print(f"refsim.warm: compiled the {name}", file=stream, flush=True)
    return names


def compile_side_by_side(stream=sys.stdout) -> list[str]:
    """Compiles every family numba's cache lacks, each in a process of its
    own, all at once, and waits for them; one line on ``stream`` first.
    Whatever the tiered start's setting: for a test session about to
    start several worker processes, each of which would otherwise compile
    the same families for itself. Returns their names."""
    names = [tier.name for tier in tiers() if numba_usable() and not tier.cached()]
    if not names:
        return []
    print(f"refsim: compiling {', '.join(names)} for this machine first "
          "(numba keeps the machine code)", file=stream, flush=True)
    children = [subprocess.Popen([sys.executable, "-m", "refsim.warm", name],
                                 stdin=subprocess.DEVNULL) for name in names]
    failed = [name for name, child in zip(names, children, strict=True) if child.wait() != 0]
    if failed:
        raise RuntimeError(f"refsim.warm: compiling {', '.join(failed)} failed")
    return names


def start_in_background(stream) -> subprocess.Popen | None:
    """Starts ``python -m refsim.warm`` in a process of its own when some
    family is cold, saying so on ``stream``; else None. Its output is
    discarded; it goes on if the command ends first."""
    cold = cold_tiers()
    if not cold:
        return None
    names = ", ".join(tier.name for tier in cold)
    print(f"refsim: compiling kernels for this machine in the background ({names}; once: "
          f"numba keeps them); the readable ones answer meanwhile, with the same results",
          file=stream, flush=True)
    return subprocess.Popen([sys.executable, "-m", "refsim.warm"], stdin=subprocess.DEVNULL,
                            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                            start_new_session=True)


if __name__ == "__main__":
    if len(sys.argv) > 1:                      # one family, by name (compile_side_by_side)
        COMPILERS[" ".join(sys.argv[1:])]()
    else:
        warm()
