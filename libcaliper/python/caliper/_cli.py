"""`python3 -m caliper`: the `caliper` command's `create` and `measure` (docs/cli.md) on the
Python module. Same options, units, default regressor, validation, exit codes (0 ok, 1 runtime
error, 2 usage error, 3 implausible input) and JSON report keys as the C++ program."""
import argparse
import json
import os
import sys
import time

from . import _caliper as _c
from . import open_model_path

EXIT_OK, EXIT_RUNTIME, EXIT_USAGE, EXIT_IMPLAUSIBLE = 0, 1, 2, 3
# option -> (measurement id, is a mass)
_INPUTS = [("height", "height", False), ("weight", "weight", True),
           ("arm_span", "arm_span_fingertips", False), ("inseam", "inseam_height", False),
           ("hip_width", "hip_width", False), ("arm_length", "arm_length", False)]
_SEXES = {"f": "female", "female": "female", "woman": "female", "w": "female", "m": "male",
          "male": "male", "man": "male", "n": "neutral", "neutral": "neutral"}


class _Usage(Exception):
    """A usage error (exit code 2)."""


class _Parser(argparse.ArgumentParser):
    def error(self, message):
        raise _Usage(message)


def _sex(text):
    s = _SEXES.get(text.strip().lower())
    if s is None:
        raise _Usage(f"sex '{text}': expected female, male or neutral")
    return s


def _display(id_, value):
    if id_ == "weight":
        return f"{value:.1f} kg"
    if id_ == "volume":
        return f"{value * 1000:.1f} L"
    return f"{value * 100:.1f} cm"


def _table(inputs, achieved):
    rows = [f"{'measurement':<38}" + (f"{'input':>12}" if inputs else "") + f"{'achieved':>12}" +
            (f"{'difference':>12}" if inputs else "")]
    ids = list(dict.fromkeys(["height", "weight"] + list(inputs) + list(achieved)))
    for id_ in ids:
        row = f"{id_:<38}"
        if inputs:
            row += f"{_display(id_, inputs[id_]) if id_ in inputs else '-':>12}"
        row += f"{_display(id_, achieved[id_]) if id_ in achieved else '-':>12}"
        if inputs and id_ in inputs and id_ in achieved:
            d = achieved[id_] - inputs[id_]
            row += f"{('+' if d >= 0 else '') + _display(id_, d):>12}"
        rows.append(row)
    return "\n".join(rows) + "\n"


def _plausibility_json(p):
    return {"mahalanobis": p.mahalanobis, "dof": p.dof, "chi_square_cdf": p.cdf,
            "p_value": p.p_value, "beyond_2sd": list(p.beyond_2sd),
            "beyond_3sd": list(p.beyond_3sd), "plausible": p.plausible}


def _create(args, out, err):
    p = _Parser(prog="python3 -m caliper create",
                description="Creates an avatar from body measurements (units are required), as "
                "`caliper create`.")
    p.add_argument("--height", metavar="LENGTH", help="overall height, e.g. 168cm, 1.68m, 5ft6in")
    p.add_argument("--weight", metavar="MASS", help="body weight, e.g. 62kg or 137lb")
    p.add_argument("--arm-span", metavar="LENGTH", help="arm span, fingertip to fingertip")
    p.add_argument("--inseam", metavar="LENGTH", help="inseam height (crotch above the floor)")
    p.add_argument("--hip-width", metavar="LENGTH", help="hip width (at the trochanters)")
    p.add_argument("--arm-length", metavar="LENGTH",
                   help="arm length, acromion to wrist, arm out sideways (hanging: ~7 cm more)")
    p.add_argument("--arm-length-hanging", metavar="LENGTH",
                   help="instead of --arm-length: a tape on the relaxed hanging arm, shoulder tip "
                   "(acromion) over the elbow to the wrist's bony point on the thumb side (ANSUR "
                   "II's acromion-radiale + radiale-stylion), mapped onto the model's arm length")
    p.add_argument("-s", "--sex", help="female, male or neutral (default neutral): the open model")
    p.add_argument("-r", "--regressor", help="R2, R4, R5, R6 or noise-aware (default: R2/R4/R5 "
                   "for exactly their inputs, else noise-aware)")
    p.add_argument("-m", "--model", metavar="FILE", help="any SMPL-family model (.npz/.pkl)")
    p.add_argument("--regressors", metavar="FILE", help="regressors saved by `caliper train "
                   "--save` (else trained now)")
    p.add_argument("--mapping", metavar="FILE", help="real-to-virtual mapping (.json or .csv)")
    p.add_argument("-o", "--out", metavar="FILE", help="write the avatar: .glb, .gltf, .obj, .ply")
    p.add_argument("--png", metavar="FILE", help="not available from Python (use `caliper "
                   "create --png`)")
    p.add_argument("--json", action="store_true", help="print the JSON report")
    p.add_argument("--exact-inputs", action="store_true", help="refine R2-R6 betas so that "
                   "every input is reproduced exactly")
    p.add_argument("--no-shape-curve", action="store_true", help="plain regressors (R2-R6) as "
                   "in the paper: from the mean body, not from the general population's body of "
                   "the height and weight")
    p.add_argument("--population", metavar="NAME", help="the person is of this population the "
                   "model carries (ansur2: US Army soldiers, nhanes: US adults): the noise-aware "
                   "regressor with its shapes as the prior")
    p.add_argument("--force", action="store_true", help="create the avatar even when an input "
                   "is outside the hard limits")
    p.add_argument("-q", "--quiet", action="store_true", help="print nothing but warnings")
    a = p.parse_args(args)
    if a.png:
        raise _Usage("--png: rendering is not part of the Python module; use `caliper create "
                     "--png`")
    t_start = time.perf_counter()
    inputs = {}
    for name, id_, mass in _INPUTS:
        text = getattr(a, name)
        if text is not None:
            what = "--" + name.replace("_", "-")
            try:
                inputs[id_] = _c.parse_mass(text) if mass else _c.parse_length(text)
            except _c.InvalidInputError as e:
                raise _Usage(str(e).replace(("mass" if mass else "length") + " '", what + " '", 1))
    hanging = None
    if a.arm_length_hanging is not None:
        if "arm_length" in inputs:
            raise _Usage("give --arm-length (arm out sideways) or --arm-length-hanging (arm "
                         "hanging), not both")
        try:
            hanging = _c.parse_length(a.arm_length_hanging)
        except _c.InvalidInputError as e:
            raise _Usage(str(e).replace("length '", "--arm-length-hanging '", 1))
        inputs["arm_length"] = hanging  # judged as measured, mapped once the model is loaded
    sex = _sex(a.sex) if a.sex else "neutral"
    try:
        regressor = (_c.default_regressor(inputs) if a.regressor is None else
                     _c.normalise_regressor(a.regressor))
    except _c.InvalidInputError as e:
        raise _Usage("--" + str(e))
    if a.population is not None:
        if a.regressor is not None and regressor != "noise-aware":
            raise _Usage("--population takes the noise-aware regressor (the population is its "
                         f"prior); leave out --regressor {regressor}")
        regressor = "noise-aware"
    if not inputs:
        raise _Usage("no measurements given; give at least --height (and usually --weight)")
    if regressor != "noise-aware":
        missing = [o for o, id_, _ in _INPUTS if id_ in _c.regressor_inputs(regressor) and
                   id_ not in inputs]
        if missing:
            raise _Usage(f"regressor {regressor} needs " +
                         ", ".join("--" + o.replace("_", "-") for o in missing) +
                         " (or choose --regressor noise-aware, which takes any subset)")
    if a.out and os.path.splitext(a.out)[1].lower() not in (".glb", ".gltf", ".obj", ".ply"):
        raise _Usage(f"--out {a.out}: use a .glb, .gltf, .obj or .ply file name")
    warnings = []
    errors = []
    for msg in _c.validate_measurements(inputs):
        # A value no body has (not a number, zero or negative) is refused even with --force.
        value = inputs.get(msg["id"])
        impossible = msg["severity"] == "error" and value is not None and not value > 0.0
        (errors if msg["severity"] == "error" and (not a.force or impossible)
         else warnings).append(msg["message"])
    if errors:
        err.write("caliper: " + ("implausible input: " if len(errors) == 1 else
                                 "implausible inputs: ") + "; ".join(errors) + "\n")
        return EXIT_IMPLAUSIBLE
    for w in warnings:
        err.write(f"caliper: warning: {w}\n")

    if a.model:
        if not os.path.isfile(a.model):
            raise _c.Error(f"{a.model}: model file not found (--model expects an SMPL-family "
                           ".npz or .pkl file)")
        model_path = a.model
    else:
        model_path = open_model_path(sex)
    t0 = time.perf_counter()
    model = _c.load_model(model_path)
    t1 = time.perf_counter()
    regs = (_c.load_regressors(a.regressors, model) if a.regressors else
            _c.train_regressors(model))
    t2 = time.perf_counter()
    if not a.model and model.gender and model.gender != sex:
        err.write(f"caliper: warning: the model's gender is {model.gender}\n")
    mapping = _c.load_mapping(a.mapping) if a.mapping else None
    t_create = time.perf_counter()
    arm_map = None
    if hanging is not None:
        try:
            arm_map = _c.hanging_arm_map(model)
        except _c.Error as e:
            raise _c.Error("--arm-length-hanging: this model cannot swing its arms down to map "
                           f"the value ({e}); give --arm-length, taken with the arm out sideways")
        inputs["arm_length"] = arm_map["a"] * hanging + arm_map["b"]
    try:
        avatar = _c.create(model, regs, inputs, regressor=regressor, exact_inputs=a.exact_inputs,
                           force=True, mapping=mapping, shape_curve=not a.no_shape_curve,
                           population=a.population)
    except _c.InvalidInputError as e:
        if a.population is None or "carries no population" not in str(e):
            raise
        raise _Usage(f"--population {a.population}: {e}")
    create_s = time.perf_counter() - t_create
    pl = avatar.plausibility
    if not pl.plausible:
        w = (f"unusual body shape: the avatar is outside the usual range (Mahalanobis distance "
             f"{str(pl.mahalanobis)[:5]}, {len(pl.beyond_3sd)} components beyond 3 SD): check the "
             "measurements" + ("" if regressor == "noise-aware" else
                               " or try --regressor noise-aware"))
        warnings.append(w)
        err.write(f"caliper: warning: {w}\n")
    t_write = time.perf_counter()
    written = []
    if a.out:
        extras = {} if a.model else {"open_model_sex": sex}
        avatar.save(a.out, extras=extras)
        written.append(a.out)
    write_s = time.perf_counter() - t_write
    total_s = time.perf_counter() - t_start
    if a.json:
        j = {"command": "create", "version": f"caliper {_c.__version__}",
             "model": {"path": model_path, "name": model.name, "gender": model.gender,
                       "vertices": model.num_vertices, "betas": model.num_betas},
             "regressor": regressor, "units": {"length": "m", "weight": "kg", "volume": "m3"},
             "input": avatar.input}
        if a.population is not None:
            j["population"] = a.population
        if arm_map is not None:
            j["hanging_arm"] = {"measured": hanging, "arm_length": inputs["arm_length"],
                                "slope": arm_map["a"], "intercept": arm_map["b"],
                                "fit_rms": arm_map["fit_rms"], "bodies": arm_map["count"]}
        if mapping is not None:
            j["mapped_input"] = avatar.mapped
        achieved = avatar.achieved
        j["achieved"] = achieved
        j["difference"] = {k: achieved[k] - v for k, v in avatar.mapped.items() if k in achieved}
        j["betas"] = avatar.betas.tolist()
        if avatar.betas_sd is not None:
            j["betas_sd"] = avatar.betas_sd.tolist()
        j["plausibility"] = _plausibility_json(pl)
        j["warnings"] = warnings
        j["written"] = written
        j["timing_seconds"] = {"load_model": t1 - t0, "train_regressors": t2 - t1,
                               "create": create_s, "write_avatar": write_s, "total": total_s}
        out.write(json.dumps(j, indent=2) + "\n")
        return EXIT_OK
    if a.quiet:
        return EXIT_OK
    prior = "" if a.population is None else f", prior: the model's population '{a.population}'"
    out.write(f"model: {model.name or '(unnamed)'} ({model.gender or '?'}, {model_path})\n"
              f"regressor: {regressor}{prior}\n")
    if arm_map is not None:
        b = arm_map["b"]
        out.write(f"arm length taken hanging: {_display('arm_length', hanging)} -> the model's arm "
                  f"length (arm out sideways) {_display('arm_length', inputs['arm_length'])} "
                  f"({arm_map['a']:.3f} x hanging {'-' if b < 0 else '+'} "
                  f"{_display('arm_length', abs(b))}, RMS {_display('arm_length', arm_map['fit_rms'])}"
                  f" over {arm_map['count']} bodies of the model)\n")
    out.write("\n")
    out.write(_table(avatar.mapped, avatar.achieved))
    out.write("\nbetas: " + " ".join(f"{b:.3f}" for b in avatar.betas) + "\n")
    if avatar.betas_sd is not None:
        out.write("betas posterior SD: " + " ".join(f"{b:.3f}" for b in avatar.betas_sd) + "\n")
    out.write(f"plausibility: Mahalanobis distance {pl.mahalanobis:.2f} over {pl.dof} "
              f"components, chi-square p = {pl.p_value:.3f} "
              f"({'plausible body shape' if pl.plausible else 'unusual body shape: outside the usual range'})\n")
    for f in written:
        out.write(f"wrote {f}\n")
    out.write(f"time: load model {(t1 - t0) * 1e3:.1f} ms, train regressors {(t2 - t1) * 1e3:.1f} "
              f"ms, create {create_s * 1e3:.1f} ms, write {write_s * 1e3:.1f} ms, total "
              f"{total_s * 1e3:.1f} ms\n")
    return EXIT_OK


def _measure(args, out, err):
    p = _Parser(prog="python3 -m caliper measure",
                description="Measures a rest-pose avatar (.glb/.gltf) or a model with betas, as "
                "`caliper measure`.")
    p.add_argument("avatar", nargs="?", help="avatar file (.glb or .gltf)")
    p.add_argument("-m", "--model", metavar="FILE", help="the model (default: the open model)")
    p.add_argument("-s", "--sex", help="female, male or neutral: which open model (default: the "
                   "one a `caliper create` GLB names, else neutral)")
    p.add_argument("-b", "--betas", metavar="LIST", help="comma-separated betas")
    p.add_argument("--no-circumferences", action="store_true", help="skip the circumferences")
    p.add_argument("--json", action="store_true", help="print JSON (SI units: m, kg, m3)")
    a = p.parse_args(args)
    if a.avatar is None and a.betas is None and a.model is None:
        raise _Usage("give an avatar file, or --betas (and optionally --model)")
    if a.avatar is not None and a.betas is not None:
        raise _Usage("give either an avatar file or --betas, not both")
    mesh = None
    sex, sex_from = "neutral", "default"
    if a.avatar is not None:
        if os.path.splitext(a.avatar)[1].lower() not in (".glb", ".gltf"):
            raise _Usage(f"{a.avatar}: python3 -m caliper measures .glb/.gltf avatars; use the "
                         "caliper program for .obj/.ply")
        mesh = _c.read_gltf(a.avatar)
    if a.sex:
        sex, sex_from = _sex(a.sex), "--sex"
    elif not a.model and mesh is not None and "open_model_sex" in mesh["extras"]:
        sex, sex_from = _sex(mesh["extras"]["open_model_sex"]), "the avatar file"
    model_path = a.model if a.model else open_model_path(sex)
    model = _c.load_model(model_path)
    betas = None
    if mesh is not None:
        source = a.avatar
        if mesh["vertices"].shape[0] != model.num_vertices:
            raise _c.Error(f"{source}: the avatar has {mesh['vertices'].shape[0]} vertices but "
                           f"the model {model_path} has {model.num_vertices}; measure with the "
                           "model it was made from (--model FILE or --sex)")
        m = _c.measure(model, mesh["vertices"], circumferences=not a.no_circumferences)
    else:
        source = model_path
        try:
            betas = [float(x) for x in a.betas.split(",")] if a.betas else []
        except ValueError:
            raise _Usage(f"--betas {a.betas}: expected a comma-separated list of numbers")
        if len(betas) > model.num_betas:
            raise _Usage(f"--betas: {len(betas)} values, but the model has {model.num_betas} "
                         "shape components")
        m = _c.measure(model, betas=betas, circumferences=not a.no_circumferences)
    if a.json:
        j = {"command": "measure", "source": source, "model": model_path}
        if not a.model:
            j["model_chosen_by"] = sex_from
        if betas:
            j["betas"] = betas
        j["units"] = {"length": "m", "weight": "kg", "volume": "m3"}
        j["measurements"] = m
        out.write(json.dumps(j, indent=2) + "\n")
        return EXIT_OK
    out.write(f"source: {source}\nmodel: {model_path} ({model.gender or '?'})" +
              ("" if a.model else f"; open model chosen by {sex_from}") + "\n")
    if betas:
        out.write("betas: " + " ".join(f"{b:.3f}" for b in betas) + "\n")
    out.write("\n" + _table({}, m))
    return EXIT_OK


_COMMANDS = {"create": _create, "measure": _measure}
_HELP = ("usage: python3 -m caliper <command> [options]\n\n"
         "The `caliper` command's create and measure on the Python module (docs/library.md).\n\n"
         "commands:\n"
         "  create     measurements in (with units), an avatar (.glb/.gltf/.obj/.ply) and a "
         "report out\n"
         "  measure    all measurements, volume and weight of a .glb/.gltf avatar or of a model "
         "+ betas\n\n`python3 -m caliper <command> --help` for a command's options.\n")


def main(argv, out=None, err=None):
    """Runs one command; returns its exit code (0 ok, 1 runtime, 2 usage, 3 implausible)."""
    out = out or sys.stdout
    err = err or sys.stderr
    if not argv or argv[0] in ("-h", "--help", "help"):
        out.write(_HELP)
        return EXIT_OK if argv else EXIT_USAGE
    if argv[0] == "--version":
        out.write(f"caliper {_c.__version__} (python)\n")
        return EXIT_OK
    command = _COMMANDS.get(argv[0])
    try:
        if command is None:
            raise _Usage(f"unknown command '{argv[0]}' (expected create or measure)")
        return command(argv[1:], out, err)
    except _Usage as e:
        err.write(f"caliper: {e}\n")
        return EXIT_USAGE
    except (_c.Error, OSError) as e:
        err.write(f"caliper: {e}\n")
        return EXIT_RUNTIME
