"""The report's templates, installed as package data ``refsim.bundled.templates``."""
