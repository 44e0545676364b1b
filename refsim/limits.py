"""The limits refsim sets on its inputs, in one place, each with its reason.

Every input enters through a validation that refuses values beyond these with
one error naming the file and key or the argument (docs/design.md, Errors), so that
no input can overflow the arithmetic, allocate without bound or run for days.
"""

from __future__ import annotations

#: Every number in a scene has magnitude at most ``MAX_MAGNITUDE``, and every
#: quantity that must be positive (a mass, a scale, a size, a step) at least
#: ``MIN_POSITIVE``. The loop multiplies a handful of scene quantities at a
#: time (an energy is a mass times a speed squared; an inertia a mass times a
#: length squared, inverted), and in this range no such product comes near
#: float64's overflow (1.8e308) or its smallest normal number (2.2e-308),
#: while no scene in any unit system comes near the range's ends.
MAX_MAGNITUDE = 1e50
MIN_POSITIVE = 1e-50

#: At most this many steps in one run (an interval over a step): a guard
#: against a step such as 1e-12 or 5e-324 that would run for days or ask for
#: terabytes. The simulation loop, the particle system and the integrator
#: refuse more; a scene's own limit (below) may be raised up to it.
MAX_STEPS = 100_000_000

#: At most this many steps in a scene (its ``integration.duration`` over its
#: ``step``) unless the caller raises the limit (``load_scene(...,
#: max_steps=N)``, ``refsim run --max-steps N``), up to ``MAX_STEPS``. The
#: bundled scenes take thousands of steps and the report's longest runs
#: hundreds of thousands; a scene a hundred times beyond that most likely
#: has a duration or a step in the wrong unit, and would hold the machine
#: for hours before anything is written, so it is refused while it is read.
DEFAULT_MAX_STEPS = 10_000_000

#: The largest trajectory :func:`refsim.solvers.integrate.solve_fixed_step`
#: allocates, in bytes: a longer run or a larger state is refused before any
#: allocation.
MAX_RESULT_BYTES = 4 * 2**30

#: At most this many particles in one system. A step of RK4 holds about eight
#: arrays of N x 3 floats (the state, four stage derivatives and scratch):
#: 2e7 particles are about 4 GB, the most a 2-core machine of the kind refsim
#: is tested on (24 GB) runs comfortably beside its output.
MAX_PARTICLES = 20_000_000

#: The largest input file refsim reads, in bytes. A model's triangles are
#: read whole into memory (a binary STL of 2 GiB holds 42 million triangles,
#: far more than any collision scene needs); a scene is a few kilobytes of
#: TOML, so 16 MiB leaves room for thousands of bodies while refusing at once
#: a log or a disk image given as a scene.
MAX_MODEL_BYTES = 2 * 2**30
MAX_SCENE_BYTES = 16 * 2**20

#: The deepest nesting of arrays and inline tables a scene may have. A scene
#: needs three (a body's rotation is an array of arrays inside an array of
#: tables); Python's TOML parser recurses once per level and would overflow
#: the stack at about a thousand.
MAX_SCENE_NESTING = 32
