"""The hardening probe: bad inputs and security properties, each case run in a forked
child with a memory cap and a timeout.

* :mod:`.harness` - :class:`~.harness.Case`, the outcome classes, :func:`~.harness.run_bounded`
  (one call in a bounded child) and :func:`~.harness.run_cases` (a list of cases in one child,
  reported case by case, a fresh child after a case that hangs or dies).
* :mod:`.values` - the bad values: fixed catalogues per kind of parameter and hypothesis
  strategies drawn deterministically (``derandomize=True``).
* ``cases_*`` - the cases per layer (crypto, security analysis, environments, key breakers,
  estimators and engine, command line); :mod:`.catalogue` collects them.
* :mod:`.count` - runs every case and prints the table per class (``python tests/probe/count.py``;
  ``PYTHONPATH=<checkout>`` probes another checkout).

The pytest entry point is ``tests/test_probe.py``.
"""
