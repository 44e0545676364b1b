"""Scene files (seed S11): schema and loader."""
