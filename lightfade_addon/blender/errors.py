"""The one exception the aging shell raises for problems a user can fix."""


class AgingError(RuntimeError):
    """A problem the user can fix; the message names the object or material and what to do."""


class YearsError(AgingError, ValueError):
    """Years that are not a finite number >= 0 (refused before anything changes)."""


def check_years(years):
    """``float(years)`` if it is a finite number >= 0, else :class:`YearsError`."""
    try:
        value = float(years)
    except (TypeError, ValueError):
        raise YearsError(f"Years must be a finite number >= 0, got {years!r}") from None
    if not (value == value and 0.0 <= value < float("inf")):
        raise YearsError(f"Years must be a finite number >= 0, got {years!r}")
    return value
