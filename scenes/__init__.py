"""The bundled scene files (TOML), installed as package data ``refsim.bundled.scenes``."""
