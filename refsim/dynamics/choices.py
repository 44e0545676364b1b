"""Where the seed is silent (AMBIGUITY) or wrong (DEVIATION) in the dynamics,
what refsim chose, and why: one list for the report to quote.

Each entry names the module where the choice is made and marked in the code
(search for its tag). The seed's formula images are lost, so the words are
all there is; where the words allow two readings, the one chosen is the one
that makes the seed's own observations possible, and the other is said.

AMBIGUITY (seed silent or unclear)

A1 ``w += T``, not ``w += h T`` (rotation_seed.contact_spin_seed). "The
   torque IS the desired change in the angular velocity ... immediately
   changed with an Euler step": a change applied at once. With ``h T`` the
   contacts would leave w practically untouched (h = 1e-3).
A2 Units of w (rotation_seed). The seed's w is in "revolutions / time", but
   its Euler step ``X += h (w x X)`` is the derivative of a rotating vector
   only when |w| is in radians per time; refsim uses rad/s throughout,
   which is what the seed's formula computes.
A3 Re-orthonormalization (rotation_seed.orientation_step_seed). The Euler
   step of the axes is not a rotation (it stretches each axis by
   ``sqrt(1 + h^2 |w|^2 sin^2)`` per step); the seed's axes are "normalized
   and orthogonal", so refsim applies Gram-Schmidt (X first) after every step.
A4 Contact vertex Pi (rotation_seed.contact_vertex_seed): the deepest vertex
   past the wall (the one that defines the crossing box face); ties (a face
   flat on the wall) go to the lowest vertex index.
A5 Vel in ``Vi = w x Pi + Vel`` is the velocity before S7's flip (the
   velocity "of the point of contact" as it hits) (rotation_seed).
A6 The centroid (simulation.Simulation): the seed's vertex average in the
   seed model; the solid's centre of mass in the corrected model. Equal for
   all bundled models but the l-beam and the star.
A7 "Exchange velocities ... about this plane" (body_response): the normal
   components along the centroid line are exchanged, the lateral ones kept;
   for a head-on collision that is the exchange of the whole velocities.
A8 The wall flip acts whenever the box is beyond the wall (walls), also when
   the body already moves inward (the seed's words, and the particle
   system's convention).
A9 Order of the stages (simulation): walls, then body-body, as the seed's
   text orders them; body-body corrections may push a body into a wall, which
   the next step's wall stage resolves.

DEVIATION (refsim departs from the seed, on purpose)

D1 Speed at the wall (walls.wall_speed): the push-back moves the body by
   ``delta`` against gravity; the flipped normal speed is the one it had at
   the wall (``v^2 + 2 a correction``, clamped at 0), so a bounce changes the
   energy only by the restitution. The seed's literal flip gains
   ``m g delta`` per bounce (apex ratios 0.18 % above e^2 at h = 1e-3 in
   scenes/bounce.toml, and more as the bounces get lower); refsim's matches
   e^2 to 1e-5. ``simulate(scene, wall_speed="seed")`` keeps the literal one.
D2 Friction as a Coulomb coefficient in the corrected model (impulse):
   ``world.friction`` is read as mu with ``|P_t| <= mu P_n``; in the seed it
   is the fraction of lateral speed removed at a bounce. The seed itself says
   the friction "should normally be proportional to the normal component of
   the incident velocity", which the Coulomb cone is.
D3 Orientation and angular velocity of a free body by Euler's equations
   with the real inertia tensor, stepped by a symmetric splitting that keeps
   the angular momentum and bounds the energy error
   (rotation_impulse.free_rotation_step), instead of the Euler step of the
   axes with the identity for the inertia.
D4 Contact between bodies (body_response.contact_geometry,
   collision.contact): the normal is the axis of least projection overlap
   among the centroid line and both bodies' axes, instead of the centroid
   line alone (wrong for boxes meeting face to face off-centre); the
   impulses act at the corners of the contact polygon of the region where
   the meshes overlap, and are solved together with the contacts of the
   walls those bodies touch (impulse.solve_island), instead of at one point
   between the bodies, one pair after another.
D5 Positional correction (body_response.separate_bodies, and the wall
   push-back in the corrected model): bodies are moved apart along the
   normal until their projections are disjoint by ``SEPARATION_SLOP``, so no
   interpenetration persists (claim C11).
D6 Restitution threshold (impulse.RESTITUTION_THRESHOLD = 0.05 m/s): slower
   contacts get no restitution, so resting bodies settle; and in the
   corrected model the speed at the wall (D1) is applied only to bounces,
   not to resting contact, where it would cancel gravity at the centroid
   with no torque and let a cube balance on an edge.
D7 ``rotation = "off"``: the bodies do not turn and w is reported as 0,
   whatever the scene's initial angular velocity.
D8 Energy-limited restitution (impulse): Poisson's restitution impulse
   ``e P_n`` is scaled down when, at several contacts with friction, it would
   make the collision add kinetic energy (a known failing of Poisson's
   hypothesis with friction; Stronge's energetic restitution avoids it
   in general at a higher cost).
D9 Retired. Friction acted during compression only (phase 1 of the impulse
   solve), so a body sliding through an impact lost ``mu |v_n|`` of lateral
   speed where Coulomb's law over the whole impact takes ``mu (1 + e) |v_n|``
   (found by the conformance kit's rigid.oblique_bounce: 4.3305 m/s against
   3.7948). The solve now runs its friction sweeps again after restitution,
   in the cone of the whole impact (refsim.dynamics.impulse, phase 3); the
   number is kept so that older reports' references stay readable.
D10 Time of impact (corrected wall response): a body found past a wall at
   the end of a step crossed it some time tau earlier; the impulse acts on
   the velocities at the wall, and the body is then carried on over tau with
   its new velocity (refsim.dynamics.walls.crossing_time, bounce_advance),
   so that a bounce is not up to a step late. The orientation is not carried
   on (it turned with the spin before the impact over tau). A body resting
   on the wall is held by every vertex past it; an impact acts at the
   deepest of them (refsim.dynamics.rotation_impulse.wall_contacts).
"""

from __future__ import annotations

import re

CHOICES_TEXT = __doc__


def choices() -> list[tuple[str, str]]:
    """``[(tag, text), ...]`` for every entry above, e.g. ``("A1", "w += T ...")``,
    with the text on one line, for the report."""
    entries = re.findall(r"^([AD]\d+) (.*?)(?=^[AD]\d+ |^DEVIATION|\Z)", __doc__,
                         flags=re.M | re.S)
    return [(tag, " ".join(text.split())) for tag, text in entries]
