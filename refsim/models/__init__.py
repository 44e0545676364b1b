"""Models (seed S1): meshes, the AC3D reader and writer, generated shapes."""
