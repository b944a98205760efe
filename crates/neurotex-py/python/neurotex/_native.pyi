"""Type stubs of the compiled half of neurotex. Use the functions of :mod:`neurotex`,
which give these their keyword signatures; the descriptions below are the tuples they
pass."""

from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

# (name, fs, mask (row-major, rows*cols) or None, label, speed_mm_s, slide_start_s,
#  slide_end_s, time stamps in s or None)
Info = Tuple[
    str,
    float,
    Optional[List[bool]],
    str,
    Optional[float],
    Optional[float],
    Optional[float],
    Optional[List[float]],
]
Samples = npt.NDArray[np.floating[Any]]
# What was calibrated, as the library's serialised forms: (gain calibration, causal
# conditioning) as dicts, each None when not asked for.
Report = Tuple[Optional[Dict[str, Any]], Optional[Dict[str, Any]]]
# One headline out-of-fold prediction: (speed_mm_s, method, file, label, predicted, fold or
# None, repeat).
PredictionRow = Tuple[float, str, str, str, str, Optional[int], int]

def library_version() -> str: ...
def stage_defaults() -> Dict[str, Any]: ...
def classifier_defaults(kind: str) -> Dict[str, Any]: ...
def classifier_knobs(kind: str) -> List[str]: ...
def check_options(method: str, options: Dict[str, Any]) -> None: ...
def haralick_names(full: bool) -> List[str]: ...
def encode(
    x: Samples, info: Info, options: Dict[str, Any], baseline: Optional[str] = None
) -> Tuple[Tuple[npt.NDArray[np.uint8], Optional[npt.NDArray[np.uint8]]], Optional[Dict[str, Any]]]: ...
def features(
    recordings: Sequence[Samples],
    infos: Sequence[Info],
    method: str,
    options: Dict[str, Any],
    baseline: Optional[str] = None,
) -> Tuple[npt.NDArray[np.float64], List[str], Report]: ...
def calibrate(
    recordings: Sequence[Samples],
    infos: Sequence[Info],
    options: Dict[str, Any],
    baseline: Optional[str] = None,
) -> Report: ...
def calibrate_dataset(dir: str, options: Dict[str, Any]) -> Report: ...
def reproduce(
    out: str,
    options: Dict[str, Any],
    dataset: Optional[str] = None,
    quick: bool = False,
    seed: int = 0,
    trials: Optional[int] = None,
    seeds: Optional[int] = None,
    k: int = 5,
    standardize: bool = True,
    group_by: Optional[str] = None,
    encoder_draws: Optional[int] = None,
    command: str = "",
    folds: Optional[int] = None,
    repeats: Optional[int] = None,
    snn: bool = False,
) -> Tuple[Dict[str, Any], List[Dict[str, Any]], List[PredictionRow], float]: ...
def inspect(
    paths: List[str],
    options: Dict[str, Any],
    reading: Dict[str, Any],
    out: Optional[str] = None,
    encoder: bool = True,
    folds: int = 5,
    k: int = 5,
) -> Tuple[Dict[str, Any], List[str]]: ...
def spike_stats(spikes: npt.NDArray[np.uint8], bin_ms: int = 200) -> npt.NDArray[np.float64]: ...
def rate_volume(
    spikes: npt.NDArray[np.uint8], bin_ms: Optional[int] = 200
) -> npt.NDArray[np.float64]: ...
def glcm(
    volume: npt.NDArray[np.float64],
    three_d: bool,
    levels: int,
    distances: List[int],
    symmetric: bool,
    range: Optional[Tuple[float, float]] = None,
    mask: Optional[List[bool]] = None,
) -> npt.NDArray[np.uint64]: ...
def haralick_features(counts: npt.NDArray[np.uint64], full: bool = False) -> npt.NDArray[np.float64]: ...
def cross_validate(
    x: npt.NDArray[np.float64],
    y: List[str],
    kind: str,
    options: Dict[str, Any],
    folds: int = 5,
    seed: int = 0,
    repeats: int = 1,
) -> Dict[str, Any]: ...
def load_dataset(dir: str, indices: Optional[List[int]] = None) -> Dict[str, Any]: ...
def dataset_events(
    dir: str, options: Dict[str, Any], indices: List[int]
) -> Tuple[
    List[Tuple[npt.NDArray[np.int64], npt.NDArray[np.int64], npt.NDArray[np.int64], npt.NDArray[np.int64]]],
    List[Dict[str, str]],
    Optional[Tuple[int, int]],
]: ...
def features_dataset(
    dir: str, method: str, options: Dict[str, Any]
) -> Tuple[npt.NDArray[np.float64], List[str], List[Dict[str, str]], Report]: ...
def save_dataset(
    dir: str,
    recordings: Sequence[Samples],
    infos: Sequence[Info],
    trials: List[Optional[int]],
    forces: List[Optional[float]],
    extra: List[Dict[str, str]],
    fs: float,
) -> None: ...
def simulate(
    out: str, seed: int, trials: int, speeds: List[float], textures: Optional[List[str]] = None
) -> None: ...
def train_model(
    recordings: Sequence[Samples],
    infos: Sequence[Info],
    method: str,
    options: Dict[str, Any],
    classifier: str,
    classifier_options: Dict[str, Any],
    fingerprint: str,
    baseline: Optional[str] = None,
    taxel: Optional[str] = None,
) -> NativeModel: ...

class NativeStream:
    def __init__(self, model: Union[NativeModel, "NativeSpikingModel"], window_s: Optional[float] = ..., decide: float = ...,
                 decide_bins: int = ..., episode: str = ..., fs: float = ...,
                 max_gap_s: float = ..., speed: Optional[float] = ...,
                 time_unit: str = ..., events: bool = ...,
                 origin: Optional[str] = ...) -> None: ...
    def push(self, values: List[float], t: Optional[float] = ...) -> List[Dict[str, Any]]: ...
    def push_event(self, t: Union[int, float], x: Optional[int] = ..., y: Optional[int] = ...,
                   p: Optional[int] = ...) -> List[Dict[str, Any]]: ...
    def reset(self) -> List[Dict[str, Any]]: ...
    def finish(self) -> List[Dict[str, Any]]: ...
    @property
    def channels(self) -> int: ...
    @property
    def frames(self) -> int: ...
    @property
    def bad_frames(self) -> int: ...

class NativeSpikingModel:
    @staticmethod
    def load(path: str) -> "NativeSpikingModel": ...
    @staticmethod
    def from_nir(path: str, like: Optional["NativeSpikingModel"] = ...) -> "NativeSpikingModel": ...
    def save(self, path: str) -> None: ...
    def write_nir(self, path: str, convention: str) -> None: ...
    def predict(self, recordings: List[Any], infos: List[Any]) -> Tuple[List[str], np.ndarray]: ...
    def predict_dataset(self, path: str) -> Tuple[List[str], np.ndarray]: ...
    @property
    def labels(self) -> List[str]: ...
    @property
    def shape(self) -> Tuple[int, int, int, int]: ...

def train_spiking_model(
    recordings: Sequence[Samples],
    infos: Sequence[Info],
    options: Dict[str, Any],
    snn_options: Dict[str, Any],
    fingerprint: str,
    baseline: Optional[str] = ...,
) -> Tuple[NativeSpikingModel, int, int, float]: ...
def is_spiking_model(path: str) -> bool: ...
def train_dataset(
    path: str,
    method: Optional[str],
    classifier: Optional[str],
    classifier_options: Dict[str, Any],
    options: Dict[str, Any],
    speeds: Optional[List[float]] = ...,
    taxel: Optional[str] = ...,
) -> Tuple[Union[NativeModel, NativeSpikingModel], Optional[Tuple[int, int, float]]]: ...
def evaluate_dataset(
    path: str,
    method: Optional[str],
    classifier: Optional[str],
    classifier_options: Dict[str, Any],
    options: Dict[str, Any],
    folds: Optional[int] = ...,
    repeats: Optional[int] = ...,
    seed: int = ...,
    speeds: Optional[List[float]] = ...,
    train_speeds: Optional[List[float]] = ...,
    test_speeds: Optional[List[float]] = ...,
    train_where: Optional[str] = ...,
    test_where: Optional[str] = ...,
    group_by: Optional[str] = ...,
    taxel: Optional[str] = ...,
    tau_ms: Optional[float] = ...,
) -> Dict[str, Any]: ...
def compare_dataset(
    path: str,
    options: Dict[str, Any],
    knn: Dict[str, Any],
    snn: Dict[str, Any],
    encodings: Optional[List[str]] = ...,
    methods: Optional[List[str]] = ...,
    classifiers: Optional[List[str]] = ...,
    speeds: Optional[List[float]] = ...,
    per: Optional[str] = ...,
    hold_out: Optional[str] = ...,
    train_where: Optional[str] = ...,
    test_where: Optional[str] = ...,
    group_by: Optional[str] = ...,
    folds: Optional[int] = ...,
    repeats: Optional[int] = ...,
    seed: int = ...,
    nested: bool = ...,
    inner_folds: Optional[int] = ...,
    tau_ms: Optional[float] = ...,
    out: Optional[str] = ...,
) -> Dict[str, Any]: ...

def datasets_list(cache: Optional[str] = ...) -> List[Dict[str, Any]]: ...
def datasets_check(name_or_path: str) -> Dict[str, Any]: ...
def datasets_fetch(
    name: str, source: Optional[str] = ..., cache: Optional[str] = ...
) -> str: ...
def datasets_path(name: str, cache: Optional[str] = ...) -> str: ...
def benchmark(
    datasets: List[str],
    out: str,
    cache: Optional[str] = ...,
    source: Optional[str] = ...,
    protocols: List[str] = ...,
    snn: bool = ...,
    folds: int = ...,
    repeats: int = ...,
    seed: int = ...,
) -> Dict[str, Any]: ...
def benchmark_shares(
    datasets: List[str],
    out: str,
    cache: Optional[str] = ...,
    source: Optional[str] = ...,
    protocols: List[str] = ...,
    snn: bool = ...,
    folds: int = ...,
    repeats: int = ...,
    seed: int = ...,
) -> List[Tuple[str, str, str, str, Optional[str]]]: ...
def benchmark_share(
    share: Tuple[str, str, str, str, Optional[str]],
    out: str,
    cache: Optional[str] = ...,
    snn: bool = ...,
    folds: int = ...,
    repeats: int = ...,
    seed: int = ...,
) -> None: ...

class NativeModel:
    @staticmethod
    def load(path: str) -> NativeModel: ...
    def save(self, path: str) -> None: ...
    def predict(
        self, recordings: Sequence[Samples], infos: Sequence[Info]
    ) -> Tuple[List[str], npt.NDArray[np.float64]]: ...
    def predict_dataset(self, path: str) -> Tuple[List[str], np.ndarray]: ...
    @property
    def labels(self) -> List[str]: ...
    @property
    def method(self) -> str: ...
    @property
    def columns(self) -> List[str]: ...
    @property
    def classifier(self) -> str: ...
    @property
    def n_training(self) -> int: ...
    @property
    def gain(self) -> float: ...
    @property
    def fingerprint(self) -> str: ...
    @property
    def gain_calibration(self) -> Optional[Dict[str, Any]]: ...
    @property
    def causal(self) -> Optional[Dict[str, Any]]: ...
    @property
    def median_duration_ms(self) -> Optional[int]: ...

class FittedClassifier:
    @staticmethod
    def fit(
        kind: str, options: Dict[str, Any], x: npt.NDArray[np.float64], y: List[int]
    ) -> FittedClassifier: ...
    @property
    def n_iter(self) -> Optional[int]: ...
    def predict(
        self, x: npt.NDArray[np.float64]
    ) -> Tuple[List[int], npt.NDArray[np.float64]]: ...
