"""Benchmarks: vinculo side by side with Exudyn, and vinculo's scaling to a million particles.

Run ``python -m vinculo.bench`` (see ``python -m vinculo.bench --help``). Exudyn is optional:
without it the comparison prints vinculo's columns only and says so. Not part of the test
suite (``tests/test_bench.py`` runs a smoke version).
"""
