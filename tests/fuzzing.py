"""Property-based tests with hypothesis: a few examples in ``make test``, many more in ``make fuzz``.

``make test`` runs each property on a fixed, derandomized set of examples
(the same every run, a few seconds in all); ``make fuzz`` sets
``RTT_FUZZ=1`` and every property gets :data:`FUZZ_FACTOR` times as many,
random ones, with hypothesis's example database (``.hypothesis/``) so a
failure found once is tried first next time.  ``RTT_FUZZ_FACTOR=N``
changes the factor.  A property names its budget with :func:`examples`.
"""

from __future__ import annotations

import os

from hypothesis import HealthCheck, settings

FUZZING = bool(os.environ.get("RTT_FUZZ"))
FUZZ_FACTOR = int(os.environ.get("RTT_FUZZ_FACTOR", "100"))
_QUIET = [HealthCheck.too_slow, HealthCheck.data_too_large, HealthCheck.function_scoped_fixture]

settings.register_profile("test", deadline=None, derandomize=True, database=None, suppress_health_check=_QUIET)
settings.register_profile("fuzz", deadline=None, suppress_health_check=_QUIET, print_blob=True)
settings.load_profile("fuzz" if FUZZING else "test")


def examples(n: int) -> settings:
    """``@examples(40)``: 40 examples in ``make test``, ``40 * FUZZ_FACTOR`` in ``make fuzz``."""
    return settings(max_examples=n * FUZZ_FACTOR if FUZZING else n)
