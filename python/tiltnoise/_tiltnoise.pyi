"""Type stubs of the extension module tiltnoise._tiltnoise (see the docstrings at run time)."""

import os
from types import MappingProxyType
from typing import Any, Literal, Mapping, Optional, Sequence, Tuple, Union, final


import numpy as np
import numpy.typing as npt

from tiltnoise._transfer import TransferFunction

__all__ = [
    "__version__",
    "_panic_for_tests",
    "Budget",
    "Coherence",
    "Fit",
    "InputFileError",
    "Mode",
    "Model",
    "MonteCarlo",
    "Params",
    "Simulation",
    "Subtraction",
    "budget",
    "budget_from_file",
    "coherence",
    "csd",
    "hdf5_version",
    "subtract",
    "welch",
]

__version__: str
hdf5_version: str

_Names = Union[str, Sequence[str]]
_Path = Union[str, os.PathLike[str]]
_Freqs = Union[float, npt.ArrayLike]

class InputFileError(OSError):
    """A file that was read but is not valid (layout, attribute or value)."""

@final
class Params:
    def __init__(self) -> None: ...
    @staticmethod
    def from_toml(source: Union[str, os.PathLike[str]]) -> Params: ...
    def to_toml(self) -> str: ...
    def set(self, key: str, value: float) -> Params: ...
    def update(self, values: Mapping[str, float]) -> Params: ...
    def get(self, key: str) -> float: ...
    def keys(self) -> list[Tuple[str, float, str, str]]: ...
    def to_dict(self) -> dict[str, float]: ...
    def __eq__(self, value: object, /) -> bool: ...

@final
class Mode:
    index: int
    frequency_hz: float
    omega_sq_rad2_per_s2: float
    quality_factor: float
    loss_angle_rad: float
    block: str
    overlap: float
    ratio: dict[str, float]
    seen_above_ratio: list[str]
    dominant_coordinates: list[Tuple[str, float]]
    energy_share: dict[str, float]
    seen_by: list[str]
    observable_amplitude: dict[str, float]
    shape: list[float]
    @property
    def q(self) -> float: ...
    def __reduce__(self) -> Tuple[Any, Tuple[int, bytes]]: ...
    @staticmethod
    def _from_state(version: int, state: bytes) -> Mode: ...
    def __eq__(self, other: object, /) -> bool: ...

@final
class MonteCarlo:
    samples: int
    rejected: int
    @property
    def freqs_hz(self) -> npt.NDArray[np.float64]: ...
    @property
    def sample_index(self) -> npt.NDArray[np.uintp]: ...
    mean_hz: list[float]
    std_hz: list[float]
    def __reduce__(self) -> Tuple[Any, Tuple[int, bytes]]: ...
    @staticmethod
    def _from_state(version: int, state: bytes) -> MonteCarlo: ...
    def __eq__(self, other: object, /) -> bool: ...

@final
class Fit:
    @property
    def params(self) -> Params: ...
    @property
    def parameters(self) -> list[dict[str, Any]]: ...
    @property
    def modes(self) -> list[dict[str, Any]]: ...
    @property
    def visibilities(self) -> list[dict[str, Any]]: ...
    chi2: float
    chi2_nominal: float
    prior_term: float
    dof: int
    singular_values: list[float]
    weak_directions: list[Tuple[float, list[Tuple[str, float]]]]
    iterations: int
    evaluations: int
    stop: str
    projected_gradient: float
    measured_origin: str
    def __reduce__(self) -> Tuple[Any, Tuple[int, bytes]]: ...
    @staticmethod
    def _from_state(version: int, state: bytes) -> Fit: ...
    def __eq__(self, other: object, /) -> bool: ...

@final
class Simulation:
    @property
    def dt_s(self) -> float: ...
    @property
    def fs_hz(self) -> float: ...
    @property
    def n_samples(self) -> int: ...
    @property
    def time_s(self) -> npt.NDArray[np.float64]: ...
    @property
    def observables(self) -> dict[str, npt.NDArray[np.float64]]: ...
    @property
    def coordinates(self) -> dict[str, npt.NDArray[np.float64]]: ...
    @property
    def initial_state(self) -> dict[str, dict[str, float]]: ...
    @property
    def init_source(self) -> str: ...
    @property
    def readout(self) -> dict[str, float]: ...
    @property
    def seed(self) -> int: ...
    @property
    def frequency_hz(self) -> npt.NDArray[np.float64]: ...
    @property
    def freq_hz(self) -> npt.NDArray[np.float64]: ...
    @property
    def asd(self) -> dict[str, npt.NDArray[np.float64]]: ...
    @property
    def modes_hz(self) -> list[Tuple[int, float]]: ...
    @property
    def nperseg(self) -> int: ...
    @property
    def n_welch_segments(self) -> int: ...
    @property
    def resonance_check(self) -> str: ...
    @property
    def resonances_agree(self) -> bool: ...
    @property
    def description(self) -> str: ...
    def save(self, path: _Path) -> None: ...
    def to_gwpy(self) -> dict[str, dict[str, Any]]: ...
    def to_pandas(self) -> dict[str, Any]: ...
    def plot(self) -> Any: ...
    def __reduce__(self) -> Tuple[Any, Tuple[int, bytes]]: ...
    @staticmethod
    def _from_state(version: int, state: bytes) -> Simulation: ...
    def __eq__(self, other: object, /) -> bool: ...

@final
class Model:
    def __new__(cls, params: Optional[Params] = None) -> Model: ...
    @property
    def params(self) -> Params: ...
    def modes(self) -> list[Mode]: ...
    def transfer(
        self,
        freq_hz: _Freqs,
        inputs: Optional[_Names] = None,
        outputs: Optional[_Names] = None,
        method: Literal[
            "auto", "direct", "block", "split", "polezero", "modal", "statespace", "torsion2"
        ] = "auto",
        rel_tol: float = 1e-9,
        threads: Optional[int] = None,
        out: Optional[npt.NDArray[np.complex128]] = None,
    ) -> npt.NDArray[np.complex128]: ...
    def transfer_function(
        self,
        freq_hz: _Freqs,
        inputs: Optional[_Names] = None,
        outputs: Optional[_Names] = None,
        method: Literal[
            "auto", "direct", "block", "split", "polezero", "modal", "statespace", "torsion2"
        ] = "auto",
        rel_tol: float = 1e-9,
    ) -> TransferFunction: ...
    def explain(
        self,
        freq_hz: _Freqs,
        inputs: Optional[_Names] = None,
        outputs: Optional[_Names] = None,
        rel_tol: float = 1e-9,
    ) -> str: ...
    def matrices(self) -> dict[str, Any]: ...
    def monte_carlo(self, samples: int = 10000, seed: int = 1, threads: int = 0) -> MonteCarlo: ...
    def methods(self, freq_hz: _Freqs, inputs: Optional[_Names] = None) -> dict[str, Any]: ...
    def fit(
        self,
        free: Optional[Sequence[str]] = None,
        measured: Optional[_Path] = None,
        bound_sigmas: float = 1.0,
        prior: bool = False,
        visibility: Optional[_Path] = None,
    ) -> Fit: ...
    def simulate(
        self,
        duration: float = 43200.0,
        step: float = 0.1,
        *,
        init: Union[Mapping[str, float], str, None] = None,
        init_rate: Union[Mapping[str, float], str, None] = None,
        kick_x: Optional[float] = None,
        mode_energy: float = 1e-12,
        readout: Optional[Mapping[str, float]] = None,
        seed: int = 0,
        nperseg: Optional[int] = None,
    ) -> Simulation: ...
    def __reduce__(self) -> Tuple[Any, Tuple[int, bytes]]: ...
    @staticmethod
    def _from_state(version: int, state: bytes) -> Model: ...
    def __eq__(self, other: object, /) -> bool: ...

@final
class Coherence:
    @property
    def frequency_hz(self) -> npt.NDArray[np.float64]: ...
    @property
    def axes(self) -> list[str]: ...
    @property
    def observables(self) -> list[str]: ...
    @property
    def units(self) -> dict[str, str]: ...
    @property
    def coherence(self) -> dict[str, dict[str, npt.NDArray[np.float64]]]: ...
    @property
    def multiple_coherence(self) -> dict[str, npt.NDArray[np.float64]]: ...
    @property
    def transfer(self) -> dict[str, dict[str, npt.NDArray[np.complex128]]]: ...
    @property
    def transfer_radius(self) -> dict[str, dict[str, npt.NDArray[np.float64]]]: ...
    @property
    def model(self) -> dict[str, dict[str, npt.NDArray[np.complex128]]]: ...
    @property
    def psd(self) -> dict[str, npt.NDArray[np.float64]]: ...
    @property
    def agreement(self) -> dict[str, dict[str, dict[str, Any]]]: ...
    @property
    def confidence(self) -> float: ...
    @property
    def coherence_threshold(self) -> float: ...
    @property
    def multiple_coherence_threshold(self) -> float: ...
    @property
    def notes(self) -> list[str]: ...
    def to_csv(self) -> str: ...
    def save(self, path: _Path) -> None: ...
    def __reduce__(self) -> Tuple[Any, Tuple[int, bytes]]: ...
    @staticmethod
    def _from_state(version: int, state: bytes) -> Coherence: ...
    def __eq__(self, other: object, /) -> bool: ...

@final
class Subtraction:
    @property
    def observables(self) -> list[str]: ...
    @property
    def units(self) -> dict[str, str]: ...
    @property
    def sample_rate_hz(self) -> float: ...
    @property
    def start_time(self) -> Optional[str]: ...
    @property
    def cleaned(self) -> dict[str, npt.NDArray[np.float64]]: ...
    @property
    def predicted(self) -> dict[str, npt.NDArray[np.float64]]: ...
    @property
    def frequency_hz(self) -> npt.NDArray[np.float64]: ...
    @property
    def asd(self) -> dict[str, dict[str, npt.NDArray[np.float64]]]: ...
    @property
    def estimates(self) -> list[dict[str, Any]]: ...
    @property
    def fitted_params(self) -> Params: ...
    @property
    def report(self) -> dict[str, Any]: ...
    @property
    def input_notes(self) -> list[str]: ...
    @property
    def notes(self) -> list[str]: ...
    @property
    def report_band_hz(self) -> Optional[Tuple[float, float]]: ...
    def save(self, path: _Path) -> None: ...
    def plot(self) -> Any: ...
    def __reduce__(self) -> Tuple[Any, Tuple[int, bytes]]: ...
    @staticmethod
    def _from_state(version: int, state: bytes) -> Subtraction: ...
    def __eq__(self, other: object, /) -> bool: ...

@final
class Budget:
    @property
    def frequency_hz(self) -> npt.NDArray[np.float64]: ...
    @property
    def freq_hz(self) -> npt.NDArray[np.float64]: ...
    @property
    def observables(self) -> list[str]: ...
    @property
    def terms(self) -> MappingProxyType[str, MappingProxyType[str, npt.NDArray[np.float64]]]: ...
    @property
    def total(self) -> MappingProxyType[str, npt.NDArray[np.float64]]: ...
    @property
    def units(self) -> dict[str, str]: ...
    @property
    def equivalent(self) -> dict[str, dict[str, Any]]: ...
    @property
    def segment_bands(self) -> dict[str, dict[str, Any]]: ...
    @property
    def segment_duration_s(self) -> Optional[float]: ...
    @property
    def source(self) -> dict[str, Any]: ...
    @property
    def axes(self) -> list[str]: ...
    @property
    def inputs(self) -> list[str]: ...
    @property
    def readout(self) -> dict[str, float]: ...
    @property
    def notes(self) -> list[str]: ...
    @property
    def input(self) -> dict[str, Optional[str]]: ...
    @property
    def summary(self) -> dict[str, Any]: ...
    @property
    def params(self) -> Params: ...
    def psd(self, observable: str, term: str = "total") -> npt.NDArray[np.float64]: ...
    def asd(self, observable: str, term: str = "total") -> npt.NDArray[np.float64]: ...
    def to_csv(self, *, keep_zero_columns: bool = False) -> str: ...
    def save(self, path: _Path, *, keep_zero_columns: bool = False) -> None: ...
    def to_gwpy(self) -> dict[str, dict[str, Any]]: ...
    def to_pandas(self) -> Any: ...
    def plot(self, observables: Optional[Sequence[str]] = None) -> Any: ...
    def __reduce__(self) -> Tuple[Any, Tuple[int, bytes]]: ...
    @staticmethod
    def _from_state(version: int, state: bytes) -> Budget: ...
    def __eq__(self, other: object, /) -> bool: ...

def welch(
    x: npt.ArrayLike,
    fs: float = 1.0,
    window: str = "hann",
    nperseg: int = 256,
    noverlap: Optional[int] = None,
    detrend: Union[Literal["constant"], Literal[False], None] = None,
    average: Literal["mean", "median"] = "mean",
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def csd(
    x: npt.ArrayLike,
    y: npt.ArrayLike,
    fs: float = 1.0,
    window: str = "hann",
    nperseg: int = 256,
    noverlap: Optional[int] = None,
    detrend: Union[Literal["constant"], Literal[False], None] = None,
    average: Literal["mean", "median"] = "mean",
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.complex128]]: ...
def budget(
    tilt: Union[Mapping[str, npt.ArrayLike], npt.ArrayLike],
    fs: float,
    *,
    axes: Optional[_Names] = None,
    quantity: Literal["angle", "rate"] = "angle",
    units: Optional[Mapping[str, str]] = None,
    corrected: Optional[Sequence[str]] = None,
    pendulum_tiltmeter: Optional[Sequence[str]] = None,
    gaps: Literal["reject", "interpolate"] = "reject",
    params: Union[Params, Model, None] = None,
    nperseg: Optional[int] = None,
    overlap: Optional[float] = None,
    average: Optional[Literal["mean", "median"]] = None,
    segment_duration: Optional[float] = None,
    percentiles: Optional[Tuple[float, float]] = None,
    observables: Optional[_Names] = None,
    readout: Optional[Mapping[str, Union[float, _Path]]] = None,
    term: Optional[Mapping[str, Tuple[str, _Path]]] = None,
    witness_noise: Optional[Mapping[str, Union[float, _Path, Tuple[Union[float, _Path], float]]]] = None,
    measured: Optional[_Path] = None,
    at: Optional[Sequence[float]] = None,
    at_band: Optional[float] = None,
) -> Budget: ...
def budget_from_file(
    path: _Path,
    *,
    axes: Optional[str] = None,
    quantity: Optional[Literal["angle", "rate"]] = None,
    units: Optional[Mapping[str, str]] = None,
    corrected: Optional[Sequence[str]] = None,
    pendulum_tiltmeter: Optional[Sequence[str]] = None,
    gaps: Optional[Literal["reject", "interpolate"]] = None,
    params: Union[Params, Model, None] = None,
    nperseg: Optional[int] = None,
    overlap: Optional[float] = None,
    average: Optional[Literal["mean", "median"]] = None,
    segment_duration: Optional[float] = None,
    percentiles: Optional[Tuple[float, float]] = None,
    observables: Optional[_Names] = None,
    readout: Optional[Mapping[str, Union[float, _Path]]] = None,
    term: Optional[Mapping[str, Tuple[str, _Path]]] = None,
    witness_noise: Optional[Mapping[str, Union[float, _Path, Tuple[Union[float, _Path], float]]]] = None,
    freq: Union[str, npt.ArrayLike, None] = None,
    measured: Optional[_Path] = None,
    scale: Optional[Mapping[str, float]] = None,
    at: Optional[Sequence[float]] = None,
    at_band: Optional[float] = None,
) -> Budget: ...
def coherence(
    tilt: _Path,
    measured: _Path,
    *,
    axes: Optional[str] = None,
    quantity: Optional[Literal["angle", "rate"]] = None,
    gaps: Optional[Literal["reject", "interpolate"]] = None,
    scale: Optional[Mapping[str, float]] = None,
    observables: Optional[_Names] = None,
    nperseg: Optional[int] = None,
    overlap: Optional[float] = None,
    confidence: Optional[float] = None,
    fit_band: Optional[Tuple[float, float]] = None,
    params: Union[Params, Model, None] = None,
) -> Coherence: ...
def subtract(
    tilt: _Path,
    measured: _Path,
    *,
    fit: Optional[Sequence[str]] = None,
    band: Optional[Tuple[float, float]] = None,
    report_band: Optional[Tuple[float, float]] = None,
    nperseg: Optional[int] = None,
    holdout: float = 0.25,
    max_delay: Optional[float] = None,
    witness_noise: Optional[Mapping[str, Union[float, _Path, Tuple[Union[float, _Path], float]]]] = None,
    colocated: Optional[Sequence[_Path]] = None,
    colocated_ratio: Optional[Mapping[str, float]] = None,
    readout: Optional[Mapping[str, float]] = None,
    observables: Optional[_Names] = None,
    axes: Optional[str] = None,
    quantity: Optional[Literal["angle", "rate"]] = None,
    gaps: Optional[Literal["reject", "interpolate"]] = None,
    scale: Optional[Mapping[str, float]] = None,
    units: Optional[Mapping[str, str]] = None,
    corrected: Optional[Sequence[str]] = None,
    pendulum_tiltmeter: Optional[Sequence[str]] = None,
    params: Union[Params, Model, None] = None,
) -> Subtraction: ...
def _panic_for_tests(where_: Literal["here", "detached", "thread"]) -> None:
    """Panics on purpose (tests only): a Rust panic is a PanicException, never an abort."""
