"""The HTML accuracy report: one self-contained page plus results.json."""
