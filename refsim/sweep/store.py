"""A sweep's results on disk, one file per task, written as they arrive.

Layout of a store directory::

    manifest.json            {"format": ..., "tasks": {key: {"fingerprint", "file"}}}
    results/<h>.json         one finished task: key, fingerprint, value, attempts,
                             wall_seconds; <h> = the first 32 hex digits of
                             SHA-256(key)

Each file is written whole or not at all (:func:`refsim.storage.writing.write_atomic`:
a temporary file moved over the name), so an interrupted sweep leaves only
whole results, and running the sweep again with the same store runs only the
tasks without one. A file is named by a hash of its key, not the key itself,
so that any key (slashes, spaces, any length) makes a valid file name; the
key is inside the file and checked on reading. 128 bits of hash make a clash
between two keys practically impossible (about 1e-29 for a million keys).

The manifest names every task the store has seen with its fingerprint
(:func:`refsim.sweep.tasks.fingerprint`: the function, its arguments and
its seed). A sweep whose task has a key in the manifest but another
fingerprint is refused with :class:`~refsim.errors.SweepError` before
anything runs: reusing that result would silently mix two experiments. A
sweep with more tasks than the store has seen (an extended sweep) or fewer
(a subset) is welcome; the manifest grows to the union.

Only results are stored, not failures: a task that raised is run again on
the next run (its cause may have been fixed meanwhile; a store that kept
the failure would need deleting by hand).

One sweep at a time per store: two runs writing one store at once would
both run the missing tasks (each file stays whole; the work is doubled).

Cost: O(number of tasks) to open; O(size of a result) per result.
"""

from __future__ import annotations

import json
from pathlib import Path

from refsim.errors import OutputError, SweepError
from refsim.storage.writing import write_text_atomic
from refsim.sweep.records import decode, digest, encode

#: Written into the manifest; a store of another format is refused, not guessed at.
FORMAT = "refsim.sweep store 1"

MANIFEST = "manifest.json"
RESULTS = "results"

#: Hex digits of SHA-256(key) in a result's file name (128 bits; see the module docstring).
NAME_DIGITS = 32

#: At most this many differing keys are named in the refusal (the count is always given).
NAMED_IN_ERROR = 3


class Store:
    """A store directory opened for one sweep (state: its manifest).

    Parameters
    ----------
    path : str or PathLike
        The directory; created (with its parents) when missing.
    fingerprints : dict of str to str
        The sweep's tasks, key -> fingerprint.

    Raises
    ------
    SweepError
        When the directory is not a store (files but no manifest), is a store
        of another format, or holds a task with one of these keys and another
        fingerprint.
    OutputError
        When the directory cannot be created or written.
    """

    def __init__(self, path, fingerprints: dict[str, str]):
        self.path = Path(path)
        self.fingerprints = dict(fingerprints)
        manifest = self._read_manifest()
        known = manifest["tasks"]
        differ = [key for key, fp in self.fingerprints.items()
                  if key in known and known[key]["fingerprint"] != fp]
        if differ:
            named = ", ".join(repr(key) for key in differ[:NAMED_IN_ERROR])
            extra = len(differ) - NAMED_IN_ERROR
            more = f" and {extra} more" if extra > 0 else ""
            raise SweepError(
                f"{self.path}: the store was written by another task list: {len(differ)} "
                f"task(s) have the same key but another function, arguments or seed "
                f"({named}{more}); use a new store, or delete this one to start again")
        new = {key: {"fingerprint": fp, "file": f"{RESULTS}/{file_name(key)}"}
               for key, fp in self.fingerprints.items() if key not in known}
        if new or not (self.path / MANIFEST).exists():
            known.update(new)
            self._write(self.path / MANIFEST, {"format": FORMAT, "tasks": known})

    def load(self, key: str) -> dict | None:
        """The stored record of ``key`` (keys ``value``, ``attempts``,
        ``wall_seconds``), or None when the task has not finished yet.

        Raises :class:`SweepError` for a file that does not belong to this
        task (another key or fingerprint: the store was edited by hand).
        """
        path = self.path / RESULTS / file_name(key)
        try:
            text = path.read_text(encoding="utf-8")
        except FileNotFoundError:
            return None
        try:
            record = decode(text)
            ok = record["key"] == key and record["fingerprint"] == self.fingerprints[key]
        except (ValueError, KeyError, TypeError):
            ok = False
        if not ok:
            raise SweepError(f"{path}: not the stored result of task {key!r} "
                             "(another key or fingerprint); delete the file to run the task again")
        return record

    def save(self, key: str, value_text: str, attempts: int, wall_seconds: float) -> None:
        """Store the result of ``key`` (its value as JSON text), atomically."""
        record = {"key": key, "fingerprint": self.fingerprints[key], "value": decode(value_text),
                  "attempts": attempts, "wall_seconds": wall_seconds}
        self._write(self.path / RESULTS / file_name(key), record)

    def _read_manifest(self) -> dict:
        path = self.path / MANIFEST
        try:
            text = path.read_text(encoding="utf-8")
        except FileNotFoundError:
            if self.path.is_dir() and any(self.path.iterdir()):
                raise SweepError(f"{self.path}: not a sweep store (files but no {MANIFEST}); "
                                 "give an empty or new directory") from None
            return {"format": FORMAT, "tasks": {}}
        except OSError as error:
            raise SweepError(f"{path}: cannot read the store's manifest: {error}") from None
        try:
            manifest = json.loads(text)
            if manifest["format"] != FORMAT or not isinstance(manifest["tasks"], dict):
                raise ValueError(manifest["format"])
        except (ValueError, KeyError, TypeError):
            raise SweepError(f"{path}: not a manifest of format {FORMAT!r}") from None
        return manifest

    def _write(self, path: Path, record: dict) -> None:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            write_text_atomic(path, encode(record))
        except OSError as error:
            raise OutputError(f"{path}: cannot write the sweep's store: {error}") from error


def file_name(key: str) -> str:
    """The name of ``key``'s result file: hex digits of SHA-256(key) + ``.json``."""
    return digest(key)[:NAME_DIGITS] + ".json"
