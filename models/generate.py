"""Generate the bundled models (AC3D files) in this directory.

    python models/generate.py [OUTPUT_DIR]

Every model is built from exact formulas by refsim.models.shapes and written
by refsim's own AC3D writer, so running this again gives the same bytes
(tests/models/test_bundled_models.py checks that).

| file              | triangles | what it is for                                   |
| ----------------- | --------- | ------------------------------------------------ |
| tetrahedron.ac    | 4         | the smallest closed convex body                  |
| cube.ac           | 12        | wall bounces, resting contact, stacking          |
| icosahedron.ac    | 20        | a round-ish convex body with few triangles       |
| sphere-2k.ac      | 2000      | the seed's benchmark size (geodesic, f = 10)     |
| sphere-5k.ac      | 5120      | scaling (geodesic, f = 16)                       |
| sphere-20k.ac     | 20480     | scaling (geodesic, f = 32)                       |
| torus.ac          | 2000      | non-convex, genus one                            |
| l-beam.ac         | 20        | non-convex, flat faces, sharp inner corner       |
| star.ac           | 36        | non-convex star prism                            |
| long-box.ac       | 12        | a long thin box (4 x 0.25 x 0.25)                |
| brick.ac          | 12        | three different sides (1 x 0.6 x 0.3): free      |
|                   |           | rotation about the middle axis is unstable       |
"""

from __future__ import annotations

import sys
from pathlib import Path

from refsim.models import shapes
from refsim.models.ac3d import write_ac3d
from refsim.models.mesh import Mesh

MODELS = {
    "tetrahedron.ac": lambda: shapes.tetrahedron(),
    "cube.ac": lambda: shapes.box((1.0, 1.0, 1.0), name="cube"),
    "icosahedron.ac": lambda: shapes.icosahedron(),
    "sphere-2k.ac": lambda: shapes.geodesic_sphere(10),
    "sphere-5k.ac": lambda: shapes.geodesic_sphere(16),
    "sphere-20k.ac": lambda: shapes.geodesic_sphere(32),
    "torus.ac": lambda: shapes.torus(),
    "l-beam.ac": lambda: shapes.l_beam(),
    "star.ac": lambda: shapes.star_prism(),
    "long-box.ac": lambda: shapes.box((4.0, 0.25, 0.25), name="long-box"),
    "brick.ac": lambda: shapes.box((1.0, 0.6, 0.3), name="brick"),
}


def named(mesh: Mesh, filename: str) -> Mesh:
    """The same mesh with its one object named after the file."""
    name = filename.removesuffix(".ac")
    return Mesh(mesh.vertices, mesh.faces, objects=(name,), name=name)


def generate(out_dir: Path) -> list[Path]:
    out_dir.mkdir(parents=True, exist_ok=True)
    written = []
    for filename, build in MODELS.items():
        path = out_dir / filename
        write_ac3d(named(build(), filename), path)
        written.append(path)
    return written


if __name__ == "__main__":
    target = Path(sys.argv[1]) if len(sys.argv) > 1 else Path(__file__).parent
    for path in generate(target):
        print(path)
