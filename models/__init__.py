"""The bundled models (AC3D), installed as package data ``refsim.bundled.models``.

``refsim.bundled.models_dir()`` finds this folder, in a source checkout and in
an installed wheel alike. ``generate.py`` wrote every ``.ac`` file here.
"""
