"""The Virtual Caliper for Python: metrically accurate, rigged avatars from body measurements.

SMPL-family body models (load, evaluate for batches of betas and poses, export GLB/glTF/OBJ/PLY)
and the paper's regressors (Pujades et al., "The Virtual Caliper", IEEE TVCG 2019), with the
project's noise-aware regressor, plausibility checks and exact-input refinement.

    import caliper
    model = caliper.open_model("female")              # or caliper.load_model("SMPL_FEMALE.pkl")
    regressors = caliper.train_regressors(model)      # once per model; or load_regressors(path)
    avatar = caliper.create(model, regressors, height="168cm", weight="62kg")
    avatar.save("avatar.glb")

Units: metres, kilograms, radians (texts with a unit such as "168cm" are accepted wherever a
measurement is given). Errors raise caliper.Error subclasses carrying the C++ message.
Documentation: docs/library.md; command line: python3 -m caliper create --help.
"""
import os as _os

from . import _paths
from ._caliper import (
    Avatar,
    BodyModel,
    Error,
    InvalidInputError,
    JsonError,
    LandmarkError,
    LinearRegressor,
    Mapping,
    ModelError,
    ModelMismatchError,
    NoiseAwareRegressor,
    Plausibility,
    Regressors,
    __version__,
    create,
    default_regressor,
    evaluate,
    glb_bytes,
    hanging_arm_map,
    load_mapping,
    load_model,
    load_regressors,
    measure,
    normalise_regressor,
    parse_length,
    parse_mass,
    plausibility,
    read_gltf,
    regressor_inputs,
    train_regressors,
    validate_measurements,
    write_gltf,
    write_obj,
    write_ply,
)

__all__ = [
    "Avatar", "BodyModel", "Error", "InvalidInputError", "JsonError", "LandmarkError",
    "LinearRegressor", "Mapping", "ModelError", "ModelMismatchError", "NoiseAwareRegressor",
    "Plausibility", "Regressors", "__version__", "assets_dir", "create", "default_regressor",
    "evaluate", "glb_bytes", "hanging_arm_map", "load_mapping", "load_model", "load_regressors", "measure",
    "normalise_regressor", "open_model", "open_model_path", "parse_length", "parse_mass", "plausibility", "read_gltf",
    "regressor_inputs", "train_regressors", "validate_measurements", "write_gltf", "write_obj",
    "write_ply",
]

SEXES = ("female", "male", "neutral")


def _assets_candidates():
    env = _os.environ.get("CALIPER_ASSETS")
    if env:
        return [env]
    here = _os.path.dirname(_os.path.abspath(__file__))
    path = _os.path.join(here, _paths.ASSETS) if _paths.ASSETS_RELATIVE else _paths.ASSETS
    return [_os.path.normpath(path)]


def assets_dir() -> str:
    """The folder of the project's data (open default models, protocols).

    $CALIPER_ASSETS when set (and then only it), else the assets of the build tree this module
    was built in, or <prefix>/share/virtual-caliper/assets when installed by cmake --install.
    Raises caliper.Error naming the folders tried when none exists.
    """
    tried = _assets_candidates()
    for d in tried:
        if _os.path.isdir(d):
            return d
    raise Error("no assets folder (tried " + ", ".join(tried) + "); set CALIPER_ASSETS="
                "/path/to/assets or load a model file with caliper.load_model(path)")


def open_model_path(sex: str = "neutral") -> str:
    """The file of the open default model for sex ('female', 'male' or 'neutral')."""
    if sex not in SEXES:
        raise InvalidInputError(f"sex {sex!r}: expected 'female', 'male' or 'neutral'")
    path = _os.path.join(assets_dir(), "models", f"caliper-{sex}.npz")
    if not _os.path.isfile(path):
        raise Error(f"the open default model {path} does not exist: build it with "
                    "caliper-modelgen (docs/models.md), set CALIPER_ASSETS to an assets folder "
                    f"that has models/caliper-{sex}.npz, or use caliper.load_model(path)")
    return path


def open_model(sex: str = "neutral", num_betas: int = -1,
               pose_blend_shapes: bool = True) -> BodyModel:
    """Loads the project's open default body model for sex ('female', 'male', 'neutral').

    MIT-licensed, SMPL-structured (24 joints, 21 shape components), see docs/models.md.
    Same options as load_model().
    """
    return load_model(open_model_path(sex), num_betas=num_betas,
                      pose_blend_shapes=pose_blend_shapes)
