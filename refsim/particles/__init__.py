"""The particle system (S10): N point masses under the seed's forces (S5),
stepped by its solvers (S6), bouncing off the world cube (S7).

Modules: ``config`` (the validated :class:`ParticleConfig`), ``forces``
(gravity and drag), ``walls`` (wall response), ``system``
(:class:`ParticleSystem`, the allocation-lean step), ``measure`` (jitter,
drag models, work-precision, throughput and memory for claims C5-C9).
"""

from refsim.particles.config import ParticleConfig
from refsim.particles.system import ParticleSystem

__all__ = ["ParticleConfig", "ParticleSystem"]
