"""What the property-based tests share: their Hypothesis settings and the values that break readers.

Every property test is derandomized (the same inputs on every run) and bounded, and
prints how many inputs it tried (the ``fuzz_counter`` fixture of ``conftest.py``).
"""

from __future__ import annotations

from hypothesis import HealthCheck, settings

__all__ = ["NASTY_VALUES", "property_settings"]


def property_settings(examples: int) -> settings:
    """Derandomized settings with ``examples`` inputs, no deadline, fixtures allowed."""
    return settings(
        max_examples=examples,
        deadline=None,
        derandomize=True,
        suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
    )


#: Values typed as ``NAME=VALUE`` text (``--set``, ``--rig-param``) that break naive readers.
NASTY_VALUES: tuple[str, ...] = (
    "", " ", "nan", "NaN", "-nan", "inf", "-inf", "infinity", "1e308", "1e309", "-1e300",
    "-1e308", "1e-320", "5e-324", "-0", "0", "-1", "1e-12", "1e6", "1e9", "1e12", "0x10",
    "0x1F", "1_000", "1,5", ",", "1,,2", "0,0", "-3,4", "100000,100000", "true", "false",
    "null", "None", "none", "abc", "'", '"', "=", "1=2", "\n", "\u00e9", "\x00", "٣",
    "99999999999999999999999999", "1" * 400, "9" * 5000, "0.1.2", "--1", "+1", ".5", "5.",
)  # fmt: skip
