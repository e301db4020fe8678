"""Names and values checked against an FMU's model description before anything runs.

Every check raises `UsageError` with one line that names the valid choices, the nearest first
(difflib), so that a typo costs one look instead of a traceback after the whole simulation.
Values are in the model description's units: SI (Pa, m, N, rad, s), and the names of an
Enumeration's items or their integer values.
"""

import difflib
import functools
import math

from .paths import UsageError, fmu_path

ENUMERATION = "Enumeration"
# FMI 3.0 type names under the FMI 2.0 ones the package uses (the variables are the same).
_FMI2_KIND = {"Float64": "Real", "Int32": "Integer"}


def fmi2_type(variable):
    """The variable's type in FMI 2.0 terms (Real, Integer, Enumeration, Boolean, String), for
    either version's model description."""
    return _FMI2_KIND.get(variable.type, variable.type)


def nearest_first(name, choices):
    """`choices` reordered: the close matches to `name` first (best first), then the rest in order."""
    choices = list(choices)
    close = difflib.get_close_matches(str(name), choices, n=len(choices), cutoff=0.6)
    return close + [c for c in choices if c not in close]


def _choices_text(name, choices, limit=12):
    ordered = nearest_first(name, choices)
    shown = ", ".join(ordered[:limit])
    return shown + (f", ... ({len(ordered)} in all)" if len(ordered) > limit else "")


@functools.lru_cache(maxsize=None)
def model_description(model):
    """FMPy's model description of the packaged `<model>.fmu` (read once per process)."""
    from fmpy import read_model_description

    return read_model_description(fmu_path(model))


@functools.lru_cache(maxsize=None)
def variables(model):
    """{name: FMPy ModelVariable} of the packaged `<model>.fmu` (do not modify)."""
    return {v.name: v for v in model_description(model).modelVariables}


def enumeration_items(variable):
    """{item name: integer value} of an Enumeration variable ({} for other types)."""
    if variable.type != ENUMERATION or variable.declaredType is None:
        return {}
    return {item.name: int(item.value) for item in variable.declaredType.items}


def _bound(variable, key):
    value = getattr(variable, key, None)
    if value is None and variable.declaredType is not None:
        value = getattr(variable.declaredType, key, None)
    if value is None and variable.type == ENUMERATION:
        items = enumeration_items(variable).values()
        value = (min if key == "min" else max)(items) if items else None
    return None if value in (None, "") else float(value)


def declared_range(variable):
    """(min, max) of a Real, Integer or Enumeration variable in its unit; None where open."""
    return _bound(variable, "min"), _bound(variable, "max")


def unit(variable):
    """The variable's unit ("" for numbers and non-Real types)."""
    u = getattr(variable, "unit", None) or (variable.declaredType.unit if variable.declaredType else None)
    return "" if u in (None, "1") else u


def check_name(model, name, allowed, what):
    """Returns the FMPy variable `name` of `model` if its causality is in `allowed`; otherwise a
    UsageError naming the variables of that kind, nearest first. `what` names the kind for the
    message ("parameter or input", "output", ...)."""
    found = variables(model)
    v = found.get(name)
    if v is None or v.causality not in allowed:
        candidates = [n for n, var in found.items() if var.causality in allowed]
        article = "an" if what[0] in "aeiou" else "a"
        prefix = f"{model}: {name!r} is not {article} {what}" + ("" if v is None else f" (it is a {v.causality})")
        raise UsageError(f"{prefix}; valid: {_choices_text(name, candidates)}")
    return v


def check_value(model, variable, value):
    """`value` converted to what FMPy sets (float, int or bool) after checking its type and the
    declared range; an Enumeration also takes an item's name. UsageError says what is allowed."""
    name, kind = variable.name, fmi2_type(variable)
    lo, hi = declared_range(variable)
    u = f" {unit(variable)}" if unit(variable) else ""
    if kind == ENUMERATION:
        items = enumeration_items(variable)
        listing = ", ".join(f"{v} {n}" for n, v in items.items())
        if isinstance(value, str):
            if value in items:
                return items[value]
            raise UsageError(f"{model}: {name} = {value!r} is not one of its items; valid: "
                             f"{_choices_text(value, list(items))}")
        if isinstance(value, bool) or not float(value).is_integer() or int(value) not in items.values():
            raise UsageError(f"{model}: {name} = {value!r} is not one of its items; valid: {listing}")
        return int(value)
    if kind == "Boolean":
        if value in (True, False, 0, 1):
            return bool(value)
        raise UsageError(f"{model}: {name} = {value!r} must be true or false")
    if kind == "String":
        return str(value)
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise UsageError(f"{model}: {name} = {value!r} must be a number{u and ' in' + u}") from None
    if kind == "Integer" and not number.is_integer():
        raise UsageError(f"{model}: {name} = {value!r} must be a whole number")
    if not math.isfinite(number) or (lo is not None and number < lo) or (hi is not None and number > hi):
        raise UsageError(f"{model}: {name} = {number:g}{u} is outside its declared range "
                         f"{'-inf' if lo is None else f'{lo:g}'} .. {'inf' if hi is None else f'{hi:g}'}{u}")
    return int(number) if kind == "Integer" else number


SETTABLE = ("parameter", "input")
READABLE = ("output", "calculatedParameter", "parameter", "input", "local", "independent")


def check_start_values(model, start_values):
    """{name: value} checked (names are parameters or inputs, values in range) and converted:
    Enumeration item names become their integers. Values in the model description's SI units."""
    return {name: check_value(model, check_name(model, name, SETTABLE, "parameter or input"), value)
            for name, value in (start_values or {}).items()}


def check_input_names(model, names):
    """Each of `names` is an input of `model`, else UsageError."""
    for name in names:
        check_name(model, name, ("input",), "input")


def check_input_values(model, name, values, times=None):
    """Every sample of input `name` (in its SI unit) lies in the declared range, else UsageError
    giving the first sample outside it and its time (`times`, s)."""
    variable = check_name(model, name, ("input",), "input")
    lo, hi = declared_range(variable)
    for k, value in enumerate(values):
        if (lo is not None and value < lo) or (hi is not None and value > hi) or value != value:
            try:
                check_value(model, variable, value)
            except UsageError as e:
                if times is None:
                    raise
                raise UsageError(f"{e} (input signal at t = {times[k]:g} s)") from None


def check_output_names(model, names):
    """Each of `names` is a variable `model` reports (outputs first in the suggestions)."""
    found = variables(model)
    for name in names:
        if name not in found:
            order = ([n for n, v in found.items() if v.causality == "output"]
                     + [n for n, v in found.items() if v.causality != "output"])
            raise UsageError(f"{model}: {name!r} is not a variable it reports; valid outputs: "
                             f"{_choices_text(name, order)}")
