# Type stubs of the compiled module (crates/python/src); private: use the `scatterfit` package.
from os import PathLike
from typing import Any, Callable, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str

_Progress = Optional[Callable[[int, int], None]]
_G = Union[float, str, None]
_F64 = npt.NDArray[np.float64]

class MeasurementHandle:
    def result_json(self) -> str: ...
    def complete(self) -> bool: ...
    def profile(self) -> dict[str, Any]: ...
    def timings(self) -> dict[str, float]: ...
    def sample_dir(self) -> str: ...
    def write(self, folder: Optional[str] = None, force: bool = False) -> list[str]: ...

def measure(
    folder: Union[str, PathLike[str]],
    *,
    method: Optional[str] = None,
    model: Optional[str] = None,
    albedo_model: Optional[str] = None,
    eta: Optional[float] = None,
    normalise_with_spectro: Optional[bool] = None,
    g: _G = None,
    g_range: Optional[Tuple[float, float]] = None,
    allow_outside_paths: bool = False,
    progress: _Progress = None,
) -> MeasurementHandle: ...
def batch(
    folders: Sequence[str],
    *,
    jobs: Optional[int] = None,
    method: Optional[str] = None,
    model: Optional[str] = None,
    albedo_model: Optional[str] = None,
    eta: Optional[float] = None,
    normalise_with_spectro: Optional[bool] = None,
    g: _G = None,
    g_range: Optional[Tuple[float, float]] = None,
    allow_outside_paths: bool = False,
    progress: _Progress = None,
) -> list[Tuple[str, Optional[MeasurementHandle], Optional[Tuple[str, str]]]]: ...
def fit_profile(
    r_mm: _F64,
    value: _F64,
    stderr: _F64,
    *,
    eta: float,
    albedo: Optional[Tuple[float, float, float]] = None,
    rd: Optional[Tuple[float, float, float]] = None,
    count: Optional[_F64] = None,
    limit: Optional[_F64] = None,
    method: str = "proposed",
    model: str = "mc",
    g: _G = None,
    g_range: Optional[Tuple[float, float]] = None,
    spot_diameter_mm: float = 1.0,
    r_min_mm: Optional[float] = None,
    normalise_with_spectro: bool = False,
    name: str = "profile",
) -> Tuple[str, bool]: ...
def profile(
    r_mm: _F64,
    sigma_s_prime: _F64,
    sigma_a: _F64,
    eta: _F64,
    g: _F64,
    *,
    model: str,
    spot_diameter_mm: Optional[float] = None,
) -> _F64: ...
def rd_total(albedo_prime: _F64, eta: _F64, g: _F64, *, model: str) -> _F64: ...
def albedo_from_rd(rd: _F64, eta: _F64, g: _F64, *, model: str) -> _F64: ...
def simulate(
    sigma_s_prime: float,
    sigma_a: float,
    eta: float,
    *,
    g: float = 0.0,
    thickness_mm: Optional[float] = None,
    photons: int = 100000,
    seed: int = 1,
    r_max_mm: float = 10.0,
    bins: int = 100,
    beam_radius_mm: Optional[float] = None,
    beam: str = "pencil",
    max_interactions: float = 1e12,
    progress: _Progress = None,
) -> dict[str, Any]: ...
def spectro_file(
    path: str, *, lab: Optional[Tuple[float, float, float]] = None, observer: int = 10, eta: Optional[float] = None
) -> Tuple[str, bool]: ...
def spectro_arrays(
    wavelengths_nm: Sequence[float],
    sci: Sequence[float],
    sce: Sequence[float],
    *,
    lab: Optional[Tuple[float, float, float]] = None,
    observer: int = 10,
    eta: Optional[float] = None,
) -> Tuple[str, bool]: ...
def export(
    result_json: str, *, to: str, scale: str = "mm", mitsuba_variant: str = "rgb", source: str = "the result"
) -> Tuple[str, list[str], Optional[str]]: ...
def mitsuba_dict(
    result_json: str, *, scale: str = "mm", mitsuba_variant: str = "rgb", source: str = "the result"
) -> Tuple[str, list[str], Optional[str]]: ...
def read_result(path: str) -> str: ...
