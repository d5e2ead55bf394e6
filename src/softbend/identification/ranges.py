"""The computational ranges of the identification settings and data, checked before any work.

A setting outside its range is a mistake, not a larger identification: lags of
10⁹ ask for a regressor of 10⁹ columns (GiB before the first fit), and the SVR
solver's time grows with the penalty C (minutes at 10⁶ on a few short
experiments, where paper A's 100 takes seconds). Each range is far
beyond what a real identification uses, yet stops such values before anything
is read or fitted, with one line naming the setting, its range and the value
given (``--input-lags: must be an integer in [1, 50]; got 1000000000``: the
error is keyed ``input_lags`` and the command line names its option).

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
input and output    [−1e50, 1e50]     fourth powers (a polynomial NARX squares its
values                                regressors, least squares squares them again)
                                      of 10⁷ samples stay below the largest double
output range        ≥ 1e-100          an output must vary (its NRMSE is over its
                                      range), by enough that the squares of its
                                      deviations are normal doubles (> 2.2e-308)
==================  ================  ==========================================
"""

from __future__ import annotations

import math
import numbers

from softbend.errors import InputError
from softbend.parameters import Range

__all__ = [
    "C_RANGE",
    "EPSILON_RANGE",
    "FOLDS_RANGE",
    "LAGS_RANGE",
    "MAX_ABS_VALUE",
    "MAX_MEMORY_MB_RANGE",
    "MIN_OUTPUT_RANGE",
    "NEAR_CONSTANT_RTOL",
    "SEED_RANGE",
    "check_integer",
    "check_lags_fit",
    "check_number",
    "check_settings",
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
#: The largest magnitude of an input or output value: a polynomial NARX squares its
#: regressors and least squares squares them again, and sums of those fourth powers
#: over 10^7 samples stay far below the largest double (1.8e308), so no fit,
#: standardization or error overflows (at 1e100 a quadratic model's one-step error did).
MAX_ABS_VALUE = 1e50
#: The smallest range of an output over the training experiments: the NRMSE is over
#: the range, and the squares of smaller deviations would leave the normal doubles.
MIN_OUTPUT_RANGE = 1e-100
#: A signal whose range over the training experiments is at most this fraction of its
#: largest magnitude is a constant up to rounding (101.325 written as 101.32500000000001):
#: near-constant, refused as a constant is.
NEAR_CONSTANT_RTOL = 1e-9

#: Integers with more digits than this are shown by their length in a message.
_SHOWN_DIGITS = 40


def _shown(value: object) -> str:
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


def check_integer(value: object, bounds: Range, key: str) -> int:
    """``value`` as an int if it is an integer (not a bool) in ``bounds``, else raise.

    Parameters
    ----------
    value : object
        The value given.
    bounds : Range
        Its declared range (inclusive bounds).
    key : str
        The setting's parameter (``"input_lags"``).

    Returns
    -------
    int
        The value.

    Raises
    ------
    InputError
        ``key: must be an integer in [low, high]; got <value>``.
    """
    integer = isinstance(value, numbers.Integral) and not isinstance(value, bool)
    if integer and isinstance(value, numbers.Integral) and bounds.contains(value):
        return int(value)  # Range compares long integers exactly
    raise InputError(
        f"must be an integer in {_integer_interval(bounds)}; got {_shown(value)}", key=key
    )


def check_number(value: object, bounds: Range, key: str) -> float:
    """``value`` as a float if it is a number (not a bool, not NaN) in ``bounds``, else raise.

    Parameters
    ----------
    value : object
        The value given.
    bounds : Range
        Its declared range.
    key : str
        The setting's parameter (``"C"``).

    Returns
    -------
    float
        The value.

    Raises
    ------
    InputError
        ``key: must be a number in (low, high]; got <value>``.
    """
    error = InputError(f"must be a number in {bounds.interval()}; got {_shown(value)}", key=key)
    if isinstance(value, bool) or not isinstance(value, numbers.Real):
        raise error
    if not bounds.contains(value):  # Range compares long integers exactly
        raise error
    return float(value)


def check_lags_fit(
    output_lags: int,
    input_lags: int,
    shortest: tuple[str, int],
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
    predicted : int, default 1
        The samples that must follow the initial conditions (regressor rows).

    Raises
    ------
    InputError
        Keyed ``output_lags`` or ``input_lags``: its range for these
        experiments, the value and the shortest experiment.
    """
    name, samples = shortest
    for key, value, most in (
        ("output_lags", output_lags, samples - predicted),
        ("input_lags", input_lags, samples - predicted + 1),
    ):
        if value > most:
            leave = "one" if predicted == 1 else str(predicted)
            raise InputError(
                f"must be an integer in [1, {max(most, 0)}] for these experiments (the "
                f"shortest, {name!r}, has {samples} sample(s), and its initial conditions "
                f"must leave {leave} to predict); got {value}",
                key=key,
            )


def check_settings(
    *,
    C: object,
    epsilon: object,
    output_lags: object,
    input_lags: object,
    max_memory_mb: object = None,
) -> None:
    """Hold the numeric identification settings to their declared ranges.

    Parameters
    ----------
    C, epsilon, output_lags, input_lags
        The values given (see :class:`~softbend.identification.study.IdentificationConfig`).
    max_memory_mb : float, optional
        Memory the identification may use, MiB; not checked when None.

    Raises
    ------
    InputError
        Keyed by the first setting out of its range: the range and the value.
    """
    check_number(C, C_RANGE, "C")
    check_number(epsilon, EPSILON_RANGE, "epsilon")
    check_integer(output_lags, LAGS_RANGE, "output_lags")
    check_integer(input_lags, LAGS_RANGE, "input_lags")
    if max_memory_mb is not None:
        check_number(max_memory_mb, MAX_MEMORY_MB_RANGE, "max_memory_mb")
