"""Hypothesis profiles of the fuzz tests: ``fuzz`` (a few examples per entry point, in the
default suite) and ``fuzz-many`` (many, under ``-m slow``). Both put a deadline on every
example; :func:`fuzzing.outcome` puts a hard one on every call (a hang fails the test)."""

from __future__ import annotations

from datetime import timedelta

from hypothesis import HealthCheck, settings

_quiet = [HealthCheck.too_slow, HealthCheck.filter_too_much, HealthCheck.data_too_large]
settings.register_profile("fuzz", max_examples=12, deadline=timedelta(seconds=30),
                          suppress_health_check=_quiet, print_blob=True)  # fmt: skip
settings.register_profile("fuzz-many", parent=settings.get_profile("fuzz"), max_examples=300)
