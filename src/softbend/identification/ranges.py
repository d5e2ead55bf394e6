"""The computational ranges of the identification settings and data, checked before any work.

A setting outside its range is a mistake, not a larger identification: lags of
10⁹ ask for a regressor of 10⁹ columns (GiB before the first fit), and the SVR
solver's time grows with the penalty C (minutes at 10⁶ on a few short
experiments, where paper A's 100 takes seconds). Each range is far
beyond what a real identification uses, yet stops such values before anything
is read or fitted, with one line naming the setting, its range and the value
given (``The '--input-lags' must be an integer in [1, 50]. Got 1000000000
instead.``).

==================  ================  ==========================================
setting             range             why
==================  ================  ==========================================
lags (na, nb)       [1, 50] samples   paper A uses 2 (eq. 27), the model search at
                                      most 3; a longer memory than 50 samples is
                                      better had by resampling than by a regressor
                                      of 50 columns per signal. Also no more than
                                      the shortest experiment leaves samples to
                                      predict after (:func:`check_lags_fit`)
``C``               (0, 1e4]          paper A: 100, the kernel search 1 to 1000;
                                      the SVR solver's time grows with C (twice
                                      paper A's at 1e4)
``epsilon``         [0, 10]           in standard deviations of the output: at a
                                      few, every sample is inside the tube and the
                                      model is a constant already
seed                [0, 2³² − 1]      the usual range of a random seed
folds               [2, 1000]         folds of whole experiments; more than the
                                      experiments are cut to their number
``max_memory_mb``   (0, 1e9] MiB      about 1 PB, beyond any machine
input and output    [−1e100, 1e100]   squares and sums of squares of 10⁷ samples
values                                stay far below the largest double (1.8e308):
                                      no standardization overflows
output range        ≥ 1e-100          an output must vary (its NRMSE is over its
                                      range), by enough that the squares of its
                                      deviations are normal doubles (> 2.2e-308)
==================  ================  ==========================================
"""

from __future__ import annotations

import math
import numbers
from typing import Any

from softbend.parameters import Range

__all__ = [
    "C_RANGE",
    "EPSILON_RANGE",
    "FOLDS_RANGE",
    "LAGS_RANGE",
    "MAX_ABS_VALUE",
    "MAX_MEMORY_MB_RANGE",
    "MIN_OUTPUT_RANGE",
    "SEED_RANGE",
    "check_integer",
    "check_lags_fit",
    "check_number",
]

#: Lags of a NARX regressor, in samples (past outputs na, inputs nb).
LAGS_RANGE = Range(
    1,
    50,
    "samples",
    why="paper A uses 2, the model search at most 3; a longer memory is better had by "
    "resampling than by a regressor of more than 50 columns per signal",
)
#: The SVR penalty C.
C_RANGE = Range(
    0,
    1e4,
    why="paper A uses 100 and the kernel search 1 to 1000; the SVR solver's time grows "
    "with C (twice paper A's at 1e4, many minutes on a few short experiments at 1e6)",
    low_inclusive=False,
)
#: The SVR tube half-width, in standard deviations of the output.
EPSILON_RANGE = Range(
    0,
    10,
    "output standard deviations",
    why="at a few standard deviations every sample lies inside the tube and the model "
    "is a constant already",
)
#: Seed of the random kernel search.
SEED_RANGE = Range(0, 2**32 - 1, why="the usual range of a random seed")
#: Cross-validation folds of whole experiments.
FOLDS_RANGE = Range(
    2, 1000, "folds", why="more folds than training experiments are cut to their number"
)
#: Memory an identification may use, MiB.
MAX_MEMORY_MB_RANGE = Range(
    0, 1e9, "MiB", why="about 1 PB, beyond any machine", low_inclusive=False
)
#: The largest magnitude of an input or output value: squares and sums of squares of
#: 10^7 samples of it stay far below the largest double (1.8e308), so no
#: standardization or error overflows.
MAX_ABS_VALUE = 1e100
#: The smallest range of an output over the training experiments: the NRMSE is over
#: the range, and the squares of smaller deviations would leave the normal doubles.
MIN_OUTPUT_RANGE = 1e-100

#: Integers with more digits than this are shown by their length in a message.
_SHOWN_DIGITS = 40


def _shown(value: Any) -> str:
    """``repr(value)``, or the digit count of an integer too long to show (or to print)."""
    if isinstance(value, numbers.Integral) and not isinstance(value, bool):
        digits = len(str(abs(int(value)))) if int(value).bit_length() < 10_000 else None
        if digits is None or digits > _SHOWN_DIGITS:
            bits = int(value).bit_length()
            return f"an integer of about {math.ceil(bits * math.log10(2)):,} digits"
    return repr(value)


def _bound(value: float) -> str:
    if math.isinf(value):
        return "inf" if value > 0 else "-inf"
    return str(int(value)) if float(value).is_integer() else f"{value:g}"


def _integer_interval(bounds: Range) -> str:
    """The interval of an integer range, its bounds written in full (``[0, 4294967295]``)."""
    left = "[" if bounds.low_inclusive else "("
    right = "]" if bounds.high_inclusive and math.isfinite(bounds.high) else ")"
    return f"{left}{_bound(bounds.low)}, {_bound(bounds.high)}{right}"


def check_integer(value: Any, bounds: Range, label: str) -> int:
    """``value`` as an int if it is an integer (not a bool) in ``bounds``, else ``ValueError``.

    Parameters
    ----------
    value : Any
        The value given.
    bounds : Range
        Its declared range (inclusive bounds).
    label : str
        The setting as the message names it, quoted: ``"'--input-lags'"`` or
        ``"'input_lags' of IdentificationConfig"``.

    Returns
    -------
    int
        The value.

    Raises
    ------
    ValueError
        ``The <label> must be an integer in [low, high]. Got <value> instead.``
    """
    integer = isinstance(value, numbers.Integral) and not isinstance(value, bool)
    if not (integer and bounds.contains(value)):  # Range compares long integers exactly
        raise ValueError(
            f"The {label} must be an integer in {_integer_interval(bounds)}. "
            f"Got {_shown(value)} instead."
        )
    return int(value)


def check_number(value: Any, bounds: Range, label: str) -> float:
    """``value`` as a float if it is a number (not a bool, not NaN) in ``bounds``, else raise.

    Parameters
    ----------
    value : Any
        The value given.
    bounds : Range
        Its declared range.
    label : str
        The setting as the message names it, quoted (``"'--C'"``).

    Returns
    -------
    float
        The value.

    Raises
    ------
    ValueError
        ``The <label> must be a number in (low, high]. Got <value> instead.``
    """
    message = f"The {label} must be a number in {bounds.interval()}. Got {_shown(value)} instead."
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise ValueError(message)
    if not bounds.contains(value):  # Range compares long integers exactly
        raise ValueError(message)
    return float(value)


def check_lags_fit(
    output_lags: int,
    input_lags: int,
    shortest: tuple[str, int],
    labels: tuple[str, str],
    *,
    predicted: int = 1,
) -> None:
    """Refuse lags that leave an experiment too few samples to predict.

    The first ``max(output_lags, input_lags - 1)`` samples of an experiment are
    its initial conditions; at least ``predicted`` samples must follow them.

    Parameters
    ----------
    output_lags, input_lags : int
        The lags (already within :data:`LAGS_RANGE`).
    shortest : tuple of (str, int)
        The name and sample count of the shortest experiment.
    labels : tuple of str
        How the message names the output lags and the input lags, quoted.
    predicted : int, default 1
        The samples that must follow the initial conditions (regressor rows).

    Raises
    ------
    ValueError
        One line naming the setting, its range for these experiments, the value
        and the shortest experiment.
    """
    name, samples = shortest
    for label, value, most in (
        (labels[0], output_lags, samples - predicted),
        (labels[1], input_lags, samples - predicted + 1),
    ):
        if value > most:
            leave = "one" if predicted == 1 else str(predicted)
            raise ValueError(
                f"The {label} must be an integer in [1, {max(most, 0)}] for these experiments: "
                f"the shortest, {name!r}, has {samples} sample(s), and its initial conditions "
                f"must leave {leave} to predict. Got {value} instead."
            )
