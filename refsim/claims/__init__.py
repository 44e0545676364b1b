"""Claims: the seed's claims C1..C12 judged from measurements.

A *claim function* is pure: it takes the records a study returned (the frozen
dataclasses of :mod:`refsim.studies`) and returns a
:class:`~refsim.claims.result.ClaimResult`: the claim's id, a verdict
("confirmed", "refuted" or "partly"), the facts the verdict rests on (every
number and boolean a sentence about it may quote), and whether it rests on
timings. It measures nothing, prints nothing and writes no sentence: the
studies measure, the views (the report, ``refsim study``) say it in words.
Every threshold a decision uses is a named constant beside its function,
with the reason for its value.

Inputs are the study records themselves, not numbers picked out of them: a
record says what was measured and how (its fields are documented where it
is defined), the same record feeds the report's tables, and a test builds
one with the real constructor. Where a claim rests on a property of an
algorithm rather than a measurement (a solver's derived order, its
stability polynomial) the caller passes it as a plain mapping, so that this
package imports nothing of refsim but study records (docs/design.md,
Architecture; tests/test_architecture.py).

Beside the claim functions, a few *findings* judge what is not a seed claim
but still turns on a threshold (an oracle agreeing within a tolerance, a
target met, a spin large enough to count as tipping): they return facts
only, and the report's sentences quote them.

- :mod:`refsim.claims.models`: the models' facts against trimesh;
- :mod:`refsim.claims.bounds`: C1, C2, the boxes against trimesh;
- :mod:`refsim.claims.collision`: C3, C4, the hierarchy's speed findings;
- :mod:`refsim.claims.solvers`: C5..C10, the solvers' oracle agreements;
- :mod:`refsim.claims.dynamics`: C11, C12, the bounce findings, the
  bounces' agreements and divergences (with their classes);
- :mod:`refsim.claims.seed`: the claims' words and the seed's terminology.
"""

from refsim.claims.result import VERDICTS, ClaimResult
from refsim.claims.seed import CLAIMS, TERMINOLOGY

__all__ = ["CLAIMS", "TERMINOLOGY", "VERDICTS", "ClaimResult"]
