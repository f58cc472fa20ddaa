"""bbm: bonded-block models of rock failure (2D, plane strain), from Python.

The same library as the ``bbm`` program (README "Python"):

    import bbm
    model = bbm.Model("examples/tunnel_voronoi.toml", threads=2)
    model.run(callback=lambda m: print(m.steps, m.cracks), every=2000)
    print(model.summary()["opening"]["failed_depth_springline"])
    xy = model.blocks.centroid          # N x 2 numpy view of the solver's state
    sxx, syy, sxy = model.blocks.stress.T

    result = bbm.ucs(width=2, height=4, seed=3)   # the CLI's options as keywords
    result["peak_stress"], result["curve"]["axial_stress"]

A model file's errors raise ``bbm.InputError`` (a ValueError) with ``file``,
``line``, ``key`` and ``message``; a numerical health stop raises
``bbm.NumericalError``.
"""

import math as _math

from ._bbm import (  # noqa: F401  (re-exported)
    BlockArrays,
    ContactArrays,
    InputError,
    Model,
    NodeArrays,
    NumericalError,
    ZoneArrays,
)
from ._bbm import _calibrate, _creep, _envelope, _labtest, _shear

__all__ = [
    "Model", "InputError", "NumericalError", "ucs", "tension", "biaxial", "brazilian", "calibrate", "to_toml",
    "envelope", "shear", "creep",
]


# --- dict -> model text -------------------------------------------------------
def _toml_key(key):
    key = str(key)
    if key and all(c.isalnum() or c in "_-" for c in key):
        return key
    return _toml_string(key)


def _toml_string(s):
    out = ['"']
    for c in s:
        if c == '"':
            out.append('\\"')
        elif c == "\\":
            out.append("\\\\")
        elif ord(c) < 0x20 or ord(c) == 0x7F:
            out.append("\\u%04x" % ord(c))
        else:
            out.append(c)
    out.append('"')
    return "".join(out)


def _toml_value(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if _math.isnan(v):
            return "nan"
        if _math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return _toml_string(v)
    if isinstance(v, dict):
        return "{ " + ", ".join(f"{_toml_key(k)} = {_toml_value(x)}" for k, x in v.items()) + " }"
    if hasattr(v, "tolist"):  # numpy arrays and scalars
        return _toml_value(v.tolist())
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_toml_value(x) for x in v) + "]"
    raise TypeError(f"cannot write {type(v).__name__} to a model file: {v!r}")


def _is_table_array(v):
    return isinstance(v, (list, tuple)) and len(v) > 0 and all(isinstance(x, dict) for x in v)


def to_toml(model):
    """The model-file text of a dict with the structure of a model file (as
    ``tomllib.load`` returns it): top-level tables become ``[table]``, lists of
    tables ``[[table]]``, deeper tables inline tables."""
    if not isinstance(model, dict):
        raise TypeError("a model is a dict of the model file's tables")
    lines = []
    for key, value in model.items():
        if isinstance(value, dict):
            lines.append(f"\n[{_toml_key(key)}]")
            lines.extend(f"{_toml_key(k)} = {_toml_value(v)}" for k, v in value.items())
        elif _is_table_array(value):
            for item in value:
                lines.append(f"\n[[{_toml_key(key)}]]")
                lines.extend(f"{_toml_key(k)} = {_toml_value(v)}" for k, v in item.items())
        else:
            lines.insert(0, f"{_toml_key(key)} = {_toml_value(value)}")
    return "\n".join(lines).lstrip("\n") + "\n"


def _from_dict(model, name="<dict>", threads=1, max_elements=0.0):
    """A model from a dict with the structure of a model file (docs/input.md), as
    ``tomllib.load(open(path, "rb"))`` gives it. Errors name the key."""
    text = to_toml(model)
    try:
        return Model._from_text(text, name, threads, max_elements)
    except InputError as e:
        # The line would be one of the generated text: name the key only.
        key = getattr(e, "key", "")
        err = InputError(f"{name}: {key + ': ' if key else ''}{getattr(e, 'message', str(e))}")
        err.file, err.line, err.key, err.message = name, 0, key, getattr(e, "message", str(e))
        raise err from None


Model.from_dict = staticmethod(_from_dict)


# --- lab tests and calibration --------------------------------------------------
def _option_args(options):
    args = []
    for key, value in options.items():
        if value is None:
            continue
        flag = "--" + key.replace("_", "-")
        if isinstance(value, bool):
            # "--flag=true": a flag (--fit-ci, --replot) takes no separate value,
            # a boolean option (--servo) takes this form as well.
            args.append(flag + ("=true" if value else "=false"))
            continue
        elif isinstance(value, (list, tuple)) or hasattr(value, "tolist"):
            items = value.tolist() if hasattr(value, "tolist") else list(value)
            if items and all(isinstance(x, (list, tuple)) for x in items):
                # Points (a softening curve) as a model file writes them: [[1.7, 0.5], [4.0, 0]].
                value = "[" + ", ".join("[" + ", ".join(repr(float(y)) for y in x) + "]" for x in items) + "]"
            else:
                value = ",".join(repr(float(x)) if isinstance(x, float) else str(x) for x in items)
        elif isinstance(value, float):
            value = repr(value)
        args += [flag, str(value)]
    return args


def _run_labtest(command, quiet, callback, options):
    if callback is not None:
        options.setdefault("frame_every", 1000)
    summary, curves = _labtest(command, _option_args(options), quiet, callback)
    if len(curves) == 1:
        summary["curve"] = curves[0]
    else:
        for entry, curve in zip(summary["per_realization"], curves):
            entry["curve"] = curve
    return summary


def ucs(quiet=True, callback=None, **options):
    """Uniaxial compression test; keyword arguments are ``bbm ucs``'s options
    (``size=0.3, pattern="trigon", realizations=3, out="dir"``...; see
    ``bbm ucs --help``). Files are written only with ``out``. Returns the dict of
    summary.json with the stress-strain curve as numpy arrays (``curve``; with
    realizations, in each ``per_realization`` entry).

    ``callback(frame)`` is called every ``frame_every`` steps of loading (1000
    unless given) with a copy of the specimen's state: ``step``,
    ``axial_strain``, ``axial_stress``, ``realization``, ``blocks`` (centroid,
    displacement, rotation, area, stress, ...) and ``contacts`` (normal_stress,
    shear_stress, normal_displacement, bonded, state, property, block_pair,
    position, edge_parameter, ...) as numpy arrays, and ``property_names``."""
    return _run_labtest("ucs", quiet, callback, options)


def tension(quiet=True, callback=None, **options):
    """Direct tension test; options as ``bbm tension`` (see ucs())."""
    return _run_labtest("tension", quiet, callback, options)


def biaxial(quiet=True, callback=None, **options):
    """Biaxial compression at ``confinement`` (Pa); options as ``bbm biaxial`` (see ucs())."""
    return _run_labtest("biaxial", quiet, callback, options)


def brazilian(quiet=True, callback=None, **options):
    """Brazilian test of a disc of diameter ``width``; options as ``bbm brazilian`` (see ucs())."""
    return _run_labtest("brazilian", quiet, callback, options)


def envelope(quiet=True, **options):
    """The strength envelope of a block model, as ``bbm envelope``: uniaxial
    compression, a tension test and biaxial tests at ``confinements`` (Pa; default
    0.1-0.5 x the UCS), ``realizations`` seeds each, with the lab-test options
    (``size=0.3, pattern="trigon"``...), or the rock of a model file
    (``model="examples/tunnel_trigon.toml"``: its block pattern, joints and
    blocks; the specimen's size and loading still from the options). Returns the
    dict of envelope.json:
    ``ucs``, ``tension``, ``levels`` (peak, sigma_ci, sigma_cd per confinement),
    ``hoek_brown`` (sigma_ci, mi, rms), ``mohr_coulomb`` (cohesion, friction_deg),
    the crack-initiation and crack-damage lines and every run. Files are written
    only with ``out``."""
    return _envelope(_option_args(options), quiet)


def shear(quiet=True, **options):
    """Direct shear test of a joint across a bonded-block specimen, as ``bbm
    shear``: ``persistence`` (rock bridges for k < 1, ``bridges`` of them),
    ``normal_stress`` (Pa; a list for a series), ``normal_stiffness`` (Pa/m; 0 =
    constant normal load), the plane's ``joint_friction``, ``joint_cohesion``...
    Returns the dict of summary.json (``levels``, ``peak_coulomb``,
    ``residual_coulomb``, ``runs``) with each run's curve (``shear_displacement``,
    ``shear_stress``, ``normal_stress``, ``dilation``, cracks) as numpy arrays in
    ``runs[i]["curve"]``. Files are written only with ``out``."""
    summary, curves = _shear(_option_args(options), quiet)
    for run, curve in zip(summary["runs"], curves):
        run["curve"] = curve
    return summary


def creep(quiet=True, **options):
    """Static fatigue of a specimen whose bonds corrode, as ``bbm creep``: per
    seed its short-term strength under a dead load, then held at each of
    ``ratios`` of it (a list) until it fails or ``max_time`` (s) passes;
    ``corrosion_rate``, ``corrosion_exponent``, ``corrosion_threshold`` and the
    rock's keywords as the lab tests'. Returns the dict of summary.json
    (``short_term``, ``ratios``, ``runs``, ``line``) with each run's curve
    (``creep_time``, ``creep_strain``, cracks) as numpy arrays in
    ``runs[i]["curve"]``. Files are written only with ``out``."""
    summary, curves = _creep(_option_args(options), quiet)
    for run, curve in zip(summary["runs"], curves):
        run["curve"] = curve
    return summary


def calibrate(quiet=True, **options):
    """Calibrates kn, ks, tensile strength and cohesion (and friction with a
    confined target: ``target_biaxial`` and ``target_confinement``,
    ``target_record`` (a CSV of sigma3, sigma1 in MPa) or ``target_mi``) to a
    laboratory record; options as ``bbm calibrate`` (``target_E=20e9,
    target_ucs=20.7e6, target_mi=12``...). Returns the dict of calibration.json
    (per iteration the confined strengths, sigma_ci/UCS and the misfit), with the
    calibrated joint property set's model-file text in ``joint_property_toml``."""
    return _calibrate(_option_args(options), quiet)
