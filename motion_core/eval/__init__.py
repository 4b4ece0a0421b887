"""Evaluation: metrics, the T2M-style evaluator, the metric suite, tables and speed benchmarks.

One command line: ``python -m motion_core.eval ...`` (see ``__main__``).
"""
