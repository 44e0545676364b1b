"""The fuzz campaign: hostile files and arguments against refsim's laws of errors.

docs/design.md, Errors: bad input raises a refsim exception naming the file, line
or key; the command line prints one line and exits non-zero, never shows a
traceback for a user's mistake, and never leaves a half-written output file.
This package checks those laws by mutation and by hostile arguments:

- :mod:`tests.fuzz.mutate`: seeded mutators of model and scene files (bytes
  in, bytes out);
- :mod:`tests.fuzz.corpus`: the files they start from (the bundled models
  and scenes, trimesh exports of a bundled model, generated long polygons);
- :mod:`tests.fuzz.cases`: one case per (family, mutator, seed, index) or
  per name (special files, ``-o`` targets, signals, arguments, and the
  findings of the earlier manual campaign): a command line, its input files
  and special nodes, and what a refusal must name;
- :mod:`tests.fuzz.runner` and :mod:`tests.fuzz.zygote`: each case run as
  ``refsim ...`` in a subprocess with a CPU-time limit, a wall-clock
  backstop and a memory limit (forked
  from a warmed interpreter, or a fresh one to confirm a failure);
- :mod:`tests.fuzz.execute`: a case's files made, the command run, what it
  left behind observed;
- :mod:`tests.fuzz.judge`: the laws, per case, and the root cause of a failure;
- :mod:`tests.fuzz.reproduce`: a failing case's files and ``repro.sh``;
- :mod:`tests.fuzz.api_worker`: hostile calls of the public API in a worker
  process under a memory limit (strategies in ``properties/fuzz/strategies.py``);
- :mod:`tests.fuzz.campaign`: ``python -m tests.fuzz.campaign --minutes N
  --seed S --out DIR``, the table and the failures with reproducers.

``make test`` runs a fixed slice (``tests/fuzz/test_fuzz_slice.py`` and
``properties/test_public_api_fuzz.py``) and the harness's own tests
(``tests/fuzz/test_harness.py``); ``make fuzz MINUTES=10`` a campaign.

Run everything from the repository root: ``tests`` has no ``__init__.py``,
so ``python -m tests.fuzz.campaign`` finds it as a namespace package in the
working directory (as pytest's ``pythonpath = ["."]`` does).
"""
