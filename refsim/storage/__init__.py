"""Files in and out: every file refsim reads or writes goes through here.

- :mod:`refsim.storage.reading`: input files, regular files only, with
  errors that name the file; bare names of bundled models and scenes.
- :mod:`refsim.storage.writing`: output files, written whole or not at all,
  and only where a file belongs.
- :mod:`refsim.storage.npz`: the .npz format, written entry by entry in
  bounded chunks and read with errors that name the entry.
- :mod:`refsim.storage.frames`: where a run's frames go as they are
  computed, kept in memory or spilled beside the output.
"""
