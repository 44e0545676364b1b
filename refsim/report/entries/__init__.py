"""The report's entries, one module per area: what each entry measures.

Each module holds its area's entry functions (``measure(run)`` of a
:class:`refsim.report.run.Study`, named after the entry: ``bounds-cost`` is
:func:`refsim.report.entries.bounds.bounds_cost`), the quick and full sizes
they pass to the studies, and the records they return where a study's own
records do not suffice. The plan (:mod:`refsim.report.plan`) names them in
its table and chooses their engines, which an entry asks its run for
(``run.engine``, ``run.optional``). Every study is imported inside the entry
function that calls it, so that the command line starts without them.
"""
