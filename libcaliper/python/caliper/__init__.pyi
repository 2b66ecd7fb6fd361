"""Type stubs of the caliper package (docs/library.md)."""
from typing import List

from ._caliper import *  # noqa: F401,F403
from ._caliper import BodyModel, __version__ as __version__

SEXES: tuple

def assets_dir() -> str: ...
def open_model_path(sex: str = "neutral") -> str: ...
def open_model(sex: str = "neutral", num_betas: int = -1,
               pose_blend_shapes: bool = True) -> BodyModel: ...
