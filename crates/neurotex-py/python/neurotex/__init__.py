"""neurotex for Python: neuromorphic tactile texture features on numpy arrays.

The same library as the ``neurotex`` command line, with the same results bit for bit:
taxel-array recordings ``(T, rows, cols)`` (or ``(T, channels)``) become spikes of
Izhikevich neurons (:func:`encode`), spike statistics (:func:`spike_stats`), rate volumes
(:func:`rate_volume`), co-occurrence matrices (:func:`glcm3d`, :func:`glcm2d`) and Haralick
features (:func:`haralick`); :func:`features` does all of it for many recordings at once,
in parallel, without the GIL. :mod:`neurotex.sklearn` wraps it for scikit-learn.
:func:`reproduce` runs the paper's analyses and writes their report; :class:`Model` trains,
saves and applies classifiers (causal ones too, for :class:`StreamClassifier`).

Defaults are the paper's (Gupta, Nakagawa, Lepora, Thakor): gain 8, RS neurons, 50 Hz
zero-phase low-pass, 200 ms bins, 16 gray levels, distances 1, 2, 4, 8.
"""

from __future__ import annotations

import hashlib
import logging
import os
import tempfile
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _native
from .errors import (
    ClassifyError,
    DataError,
    Error,
    InternalError,
    ModelError,
    NotFoundError,
    ParameterError,
    ReadWriteError,
)

__version__ = _native.library_version()
# Every stage option's default, from the library's one definition of the options.
_DEFAULTS: Dict[str, Any] = _native.stage_defaults()
# The spiking network's defaults (SpikingModel.train), from the library's.
_SNN_DEFAULTS: Dict[str, Any] = _native.classifier_defaults("snn")

HARALICK_NAMES: Tuple[str, ...] = tuple(_native.haralick_names(False))
"""Names of the paper's Haralick features, in the order :func:`haralick` returns them."""
HARALICK_FULL_NAMES: Tuple[str, ...] = tuple(_native.haralick_names(True))
"""Names of the 13 features of ``haralick(..., full=True)``."""

_log = logging.getLogger("neurotex")


def _log_said(line: str, warning: bool) -> None:
    """One line a workflow says, on the ``neurotex`` logger as it says it (the native
    workflows call this from their threads): a warning (a nested estimate not above
    chance, folds fewer than asked, ...) at WARNING, which Python shows without any logging
    set up; its progress and other lines at INFO
    (``logging.basicConfig(level=logging.INFO)`` shows them)."""
    if warning:
        _log.warning("%s", line)
    else:
        _log.info("%s", line)


METHODS = (
    "taxel", "glcm2d", "glcm3d", "all-taxels", "all-taxels-mm", "glcm3d-multi", "spectrum",
    "rates",
)
"""Feature methods of :func:`features`, as the CLI's ``--method``."""


@dataclass
class Recording:
    """One trial: samples ``x`` of shape ``(T, rows, cols)`` or ``(T, channels)``
    (float32 or float64, any memory order) with what the pipeline needs beside them.

    ``slide`` is the sliding phase ``(start_s, end_s)`` (the rest is ignored unless
    ``whole=True``); ``times`` are per-sample time stamps in seconds for irregular
    sampling (then resampled to 1 kHz); ``mask`` marks the grid cells holding a taxel
    (``(rows, cols)`` bool); ``speed`` in mm/s is needed by ``all-taxels-mm``.
    ``meta``: every column of its manifest row as text (``trial``, ``force_n`` and any
    further column such as a session or subject), for grouped cross-validation."""

    x: np.ndarray
    fs: float = 1000.0
    label: str = ""
    speed: Optional[float] = None
    slide: Optional[Tuple[float, float]] = None
    times: Optional[np.ndarray] = None
    mask: Optional[np.ndarray] = None
    name: Optional[str] = None
    meta: Dict[str, str] = field(default_factory=dict)


@dataclass
class Dataset:
    """A dataset folder in memory (:func:`load_dataset`): its recordings (with their
    sliding phases, rates and masks), labels and manifest rows."""

    recordings: List[Recording]
    rows: List[Dict[str, str]]
    columns: List[str]
    fs: float
    baseline: str
    mask: Optional[np.ndarray] = None
    path: Optional[str] = None

    @property
    def arrays(self) -> List[np.ndarray]:
        """The samples of every recording, float64 ``(T, rows, cols)``."""
        return [r.x for r in self.recordings]

    @property
    def labels(self) -> np.ndarray:
        """Every recording's texture label."""
        return np.array([r.label for r in self.recordings], dtype=object)

    @property
    def speeds(self) -> np.ndarray:
        """Every recording's sliding speed in mm/s (NaN where unknown)."""
        return np.array([np.nan if r.speed is None else r.speed for r in self.recordings])

    def column(self, name: str) -> np.ndarray:
        """Every recording's value of manifest column ``name`` (``trial``, ``force_n``, a
        session or subject column, ...): floats when every value is a number (NaN where
        empty), else text. For grouped cross-validation in scikit-learn::

            GroupKFold(5).split(X, y, groups=ds.column("trial"))

        Raises :class:`ParameterError` for a column the manifest does not have."""
        if name not in self.columns:
            raise ParameterError(
                f"invalid parameter `name`: the manifest has no column `{name}`; it has "
                + ", ".join(self.columns))
        values = [r.meta.get(name, "") for r in self.recordings]
        try:
            return np.array([np.nan if v == "" else float(v) for v in values])
        except ValueError:
            return np.array(values, dtype=object)

    def __len__(self) -> int:
        return len(self.recordings)

    def __repr__(self) -> str:
        labels = sorted({r.label for r in self.recordings})
        shown = ", ".join(labels[:8]) + (", ..." if len(labels) > 8 else "")
        return (f"Dataset({len(self.recordings)} recordings, {len(labels)} labels ({shown}), "
                f"fs={self.fs:.6g} Hz, columns={self.columns}, path={self.path!r})")


@dataclass(frozen=True)
class GainCalibration:
    """How ``gain="auto"`` chose the encoder's gain (the CLI's ``--gain auto``): the
    smallest gain of 3 significant digits at which the median firing rate, over every
    (taxel, recording) pair of the calibration recordings with any signal, reaches
    ``target_hz`` (labels are never read; at most 32 recordings, evenly spread, are used).

    ``gain``: the chosen gain; ``median_hz``: the median rate it gives; ``recordings``,
    ``pairs``: what the median ran over; ``clamped``: the target was out of reach and the
    gain is the end of the searched range (0.01 to 10000)."""

    gain: float
    target_hz: float
    median_hz: float
    recordings: int
    pairs: int
    clamped: bool

    @classmethod
    def _from_dict(cls, d: Optional[Dict[str, Any]]) -> Optional["GainCalibration"]:
        if d is None:
            return None
        return cls(gain=d["gain"], target_hz=d["target_hz"], median_hz=d["median_hz"],
                   recordings=d["recordings"], pairs=d["pairs"], clamped=d["clamped"])

    def __str__(self) -> str:
        reached = (" (target out of reach: the end of the searched range)"
                   if self.clamped else "")
        return (f"gain auto: G = {self.gain} gives a median of {self.median_hz:.1f} Hz "
                f"(target {self.target_hz} Hz) over {self.pairs} taxel x recording pairs "
                f"with signal in {self.recordings} recording(s){reached}")


@dataclass(frozen=True)
class CausalConditioning:
    """What ``causal=True`` (the CLI's ``--causal``) fixed on the training recordings,
    labels unused, so that each sample can be conditioned the moment it arrives (a
    forward-only low-pass instead of the zero-phase one): ``offsets``, each grid cell's
    resting value (row-major, float64; zeros without a baseline), and ``scale``, the
    divisor that replaces each recording's own maximum. ``recordings`` and
    ``median_duration_ms`` (the median selected phase, a stream's default window) say what
    it was fixed on, where known."""

    offsets: np.ndarray
    scale: float
    recordings: Optional[int] = None
    median_duration_ms: Optional[int] = None

    @classmethod
    def _from_dict(cls, d: Optional[Dict[str, Any]]) -> Optional["CausalConditioning"]:
        if d is None:
            return None
        # a calibration nests the conditioning; a model file holds the conditioning alone
        c = d.get("conditioning", d)
        return cls(offsets=np.array(c["offsets"], dtype=np.float64), scale=c["scale"],
                   recordings=d.get("recordings"),
                   median_duration_ms=d.get("median_duration_ms"))

    def __str__(self) -> str:
        on = "" if self.recordings is None else f" on {self.recordings} recording(s)"
        phase = ("" if self.median_duration_ms is None
                 else f" (median selected phase {self.median_duration_ms} ms)")
        return (f"causal: forward-only filter; resting values and scale {self.scale:.6f} "
                f"fixed{on}{phase}")


def _calibrations(report: Tuple[Optional[Dict[str, Any]], Optional[Dict[str, Any]]]
                  ) -> Tuple[Optional[GainCalibration], Optional[CausalConditioning]]:
    """The library's calibration report as objects, said on the ``neurotex`` logger (at
    INFO, as the CLI says it on standard error)."""
    gain = GainCalibration._from_dict(report[0])
    causal = CausalConditioning._from_dict(report[1])
    for c in (causal, gain):
        if c is not None:
            _log.info("%s", c)
    return gain, causal


class FeatureTable(tuple):
    """What :func:`features` returns: the pair ``(X, names)``, unpacked as one
    (``X, names = features(...)``), with what was calibrated beside it:
    :attr:`gain_calibration` under ``gain="auto"``, :attr:`causal` under ``causal=True``
    (``None`` otherwise)."""

    gain_calibration: Optional[GainCalibration]
    causal: Optional[CausalConditioning]

    def __new__(cls, X: np.ndarray, names: List[str],
                gain_calibration: Optional[GainCalibration] = None,
                causal: Optional[CausalConditioning] = None) -> "FeatureTable":
        self = super().__new__(cls, (X, names))
        self.gain_calibration = gain_calibration
        self.causal = causal
        return self

    def __reduce__(self) -> Any:
        return (FeatureTable, (self[0], self[1], self.gain_calibration, self.causal))

    @property
    def X(self) -> np.ndarray:
        """The features, float64 ``(n, k)``."""
        return self[0]

    @property
    def names(self) -> List[str]:
        """The ``k`` column names."""
        return self[1]


def _stage_options(**kw: Any) -> Dict[str, Any]:
    """The pipeline options the library checks; tuples become lists."""
    out = {}
    for k, v in kw.items():
        if v is None:
            continue
        if isinstance(v, (tuple, np.ndarray)):
            v = list(v)
        out[k] = v
    return out


def _samples(x: Any, what: str) -> np.ndarray:
    """``x`` as a float32 or float64 array, without copying those two."""
    a = np.asarray(x)
    if a.dtype.kind == "f" and a.dtype.itemsize in (4, 8):
        if not a.dtype.isnative:
            # Big-endian samples (a `.npy` written on such a machine, which the CLI reads
            # too): the same values in this machine's byte order.
            a = a.astype(a.dtype.newbyteorder("="))
        return a
    if a.dtype.kind in "iuf":
        return a.astype(np.float64)
    raise DataError(f"{what}: samples must be real numbers, got dtype {a.dtype}")


def _mask_list(mask: Any, what: str) -> Optional[List[bool]]:
    if mask is None:
        return None
    m = np.asarray(mask)
    if m.dtype != bool:
        raise DataError(f"{what}: the mask must be a boolean array (rows, cols)")
    return [bool(v) for v in m.ravel()]


def _recording_list(recordings: Any) -> List[Any]:
    if isinstance(recordings, Dataset):
        return list(recordings.recordings)
    if isinstance(recordings, (Recording, np.ndarray)) and not (
        isinstance(recordings, np.ndarray) and recordings.ndim == 4
    ):
        if isinstance(recordings, np.ndarray):
            raise DataError(
                f"recordings: expected a list of arrays or a 4-D array (n, T, rows, cols), "
                f"got an array of shape {recordings.shape} (use encode for one recording)"
            )
        return [recordings]
    if isinstance(recordings, np.ndarray):
        return list(recordings)  # views, no copy
    return list(recordings)


def _prepare(
    recordings: Sequence[Any],
    fs: float,
    mask: Any,
    speeds: Any = None,
) -> Tuple[List[np.ndarray], List[tuple]]:
    """Arrays and the library's per-recording descriptions."""
    arrays, infos = [], []
    if speeds is not None and len(speeds) != len(recordings):
        raise ParameterError(
            f"speeds has {len(speeds)} values for {len(recordings)} recordings"
        )
    for i, r in enumerate(recordings):
        if isinstance(r, Recording):
            name = r.name or f"recording {i}"
            a = _samples(r.x, name)
            slide = r.slide or (None, None)
            times = None if r.times is None else [float(t) for t in np.asarray(r.times)]
            m = r.mask if r.mask is not None else mask
            speed = r.speed if speeds is None else speeds[i]
            infos.append(
                (name, float(r.fs), _mask_list(m, name), str(r.label),
                 None if speed is None else float(speed), slide[0], slide[1], times)
            )
        else:
            name = f"recording {i}"
            a = _samples(r, name)
            speed = None if speeds is None else speeds[i]
            infos.append(
                (name, float(fs), _mask_list(mask, name), "",
                 None if speed is None else float(speed), None, None, None)
            )
        arrays.append(a)
    return arrays, infos


def encode(
    x: Any,
    fs: float = 1000.0,
    gain: Union[float, str] = _DEFAULTS["gain"],
    cutoff: float = _DEFAULTS["cutoff"],
    *,
    preset: str = _DEFAULTS["preset"],
    overshoot: str = _DEFAULTS["overshoot"],
    baseline: Optional[str] = None,
    encoding: str = _DEFAULTS["encoding"],
    fa_gain: float = _DEFAULTS["fa_gain"],
    whole: bool = _DEFAULTS["whole"],
    slide: Optional[Tuple[float, float]] = None,
    times: Any = None,
    mask: Any = None,
) -> Union[np.ndarray, Tuple[np.ndarray, np.ndarray]]:
    """Encodes one recording into spikes, as ``neurotex encode`` does.

    ``x``: samples ``(T, rows, cols)`` or ``(T, channels)``, float32 or float64, any
    memory order (read in place, without copying into a new numpy array). The signal is
    resampled to 1 kHz when ``fs`` differs, low-pass filtered (``cutoff`` Hz, zero-phase
    2nd-order Butterworth; 0 = off), divided by its maximum, multiplied by ``gain`` and
    fed to Izhikevich neurons of firing type ``preset`` (``overshoot="capped"``: their
    recovery reads the membrane capped at the 30 mV peak, so that rounding-level changes
    of the input leave the spikes as they are). ``gain="auto"`` (or
    ``"auto:HZ"``) calibrates the gain on this recording as ``neurotex encode --gain auto``
    does (see :class:`GainCalibration`; the choice is logged on the ``neurotex`` logger,
    and :func:`calibrate_gain` returns it).

    Returns a uint8 raster ``(T_ms, rows, cols)`` at 1 kHz (1 = spike); for
    ``encoding="sa+fa"`` the pair ``(sa, fa)``.

    Raises :class:`ParameterError` for a broken option and :class:`DataError` for bad
    samples (NaN, wrong shape, shorter than one 200 ms bin)."""
    rec = Recording(x=x, fs=fs, slide=slide, times=times, mask=mask, name="x")
    arrays, infos = _prepare([rec], fs, None)
    opts = _stage_options(gain=gain, cutoff=cutoff, preset=preset, overshoot=overshoot,
                          baseline=baseline, encoding=encoding, fa_gain=fa_gain,
                          whole=whole)
    (first, fa), gain_report = _native.encode(arrays[0], infos[0], opts)
    _calibrations((gain_report, None))
    return (first, fa) if fa is not None else first


def features(
    recordings: Any,
    method: str = "glcm3d",
    encoding: str = _DEFAULTS["encoding"],
    *,
    fs: float = 1000.0,
    mask: Any = None,
    speeds: Any = None,
    gain: Union[float, str] = _DEFAULTS["gain"],
    causal: bool = _DEFAULTS["causal"],
    preset: str = _DEFAULTS["preset"],
    overshoot: str = _DEFAULTS["overshoot"],
    cutoff: float = _DEFAULTS["cutoff"],
    baseline: Optional[str] = None,
    whole: bool = _DEFAULTS["whole"],
    levels: int = _DEFAULTS["levels"],
    bin_ms: int = _DEFAULTS["bin_ms"],
    distances: Sequence[int] = _DEFAULTS["distances"],
    symmetric: bool = _DEFAULTS["symmetric"],
    fa_gain: float = _DEFAULTS["fa_gain"],
    haralick: str = _DEFAULTS["haralick"],
    bin_widths: Sequence[int] = _DEFAULTS["bin_widths"],
    window_mm: float = _DEFAULTS["window_mm"],
    spectrum_bins: int = _DEFAULTS["spectrum_bins"],
    spectrum_bands: int = _DEFAULTS["spectrum_bands"],
    travel_mm: float = _DEFAULTS["travel_mm"],
) -> FeatureTable:
    """One feature row per recording, as ``neurotex features`` computes it.

    ``recordings``: a list of arrays ``(T, rows, cols)``, a 4-D array
    ``(n, T, rows, cols)``, a list of :class:`Recording`, a :class:`Dataset`, or the path
    of a dataset folder (read by the library, as the CLI reads it). Recordings are
    encoded and featured in parallel on all cores, without the GIL.

    ``method``: ``taxel``/``all-taxels`` (MSR, CV_ISI, Fano of every taxel),
    ``all-taxels-mm`` (per mm of travel; needs ``speeds``), ``glcm2d``, ``glcm3d`` (the
    paper's contrast, correlation, ASM), ``glcm3d-multi``, ``spectrum`` (each taxel's
    spike counts in ``spectrum_bins`` bins of the slide, Fourier magnitudes in
    ``spectrum_bands`` logarithmic bands; ``travel_mm`` > 0 reads that many mm of each
    slide and needs ``speeds``). ``encoding``: ``sa``, ``fa`` or ``sa+fa``.

    ``gain="auto"`` (or ``"auto:HZ"``, a target median rate other than 20 Hz) calibrates
    the gain on these recordings, labels unused, as ``neurotex features --gain auto`` does
    on its dataset; ``causal=True`` conditions causally, as a live stream can, with each
    taxel's resting value and one scale fixed on these recordings (``--causal``). Both are
    calibrated on every recording given: for a train/test split calibrate on the training
    recordings (:func:`calibrate_gain`, :class:`Model`, or
    :class:`neurotex.sklearn.SpikeFeatures`, which calibrates in ``fit``).

    Returns ``(X, names)``, float64 ``(n, k)`` and the ``k`` column names, as a
    :class:`FeatureTable` that also holds what was calibrated."""
    if method not in METHODS:
        raise ParameterError(
            f"invalid parameter `method`: method must be one of {', '.join(METHODS)}, "
            f"got {method}"
        )
    opts = _stage_options(
        gain=gain, causal=causal, preset=preset, overshoot=overshoot, cutoff=cutoff,
        baseline=baseline, whole=whole, levels=levels, bin_ms=bin_ms, distances=tuple(distances),
        symmetric=symmetric, encoding=encoding, fa_gain=fa_gain, haralick=haralick,
        bin_widths=tuple(bin_widths), window_mm=window_mm, spectrum_bins=spectrum_bins,
        spectrum_bands=spectrum_bands, travel_mm=travel_mm,
    )
    if isinstance(recordings, (str, os.PathLike)):
        values, names, _, report = _native.features_dataset(os.fspath(recordings), method, opts)
    else:
        dataset_baseline = recordings.baseline if isinstance(recordings, Dataset) else None
        items = _recording_list(recordings)
        if not items:
            raise DataError("no recordings to compute features of")
        arrays, infos = _prepare(items, fs, mask, speeds)
        values, names, report = _native.features(arrays, infos, method, opts, dataset_baseline)
    return FeatureTable(values, names, *_calibrations(report))


def _calibrate(recordings: Any, opts: Dict[str, Any], fs: float, mask: Any
               ) -> Tuple[Optional[GainCalibration], Optional[CausalConditioning]]:
    """What the stage options calibrate on these recordings (a folder path read by the
    library), as :func:`features` would calibrate it."""
    if isinstance(recordings, (str, os.PathLike)):
        return _calibrations(_native.calibrate_dataset(os.fspath(recordings), opts))
    dataset_baseline = recordings.baseline if isinstance(recordings, Dataset) else None
    items = _recording_list(recordings)
    arrays, infos = _prepare(items, fs, mask)
    return _calibrations(_native.calibrate(arrays, infos, opts, dataset_baseline))


def calibrate_gain(
    recordings: Any,
    target_hz: float = 20.0,
    *,
    fs: float = 1000.0,
    mask: Any = None,
    causal: bool = _DEFAULTS["causal"],
    **stage_options: Any,
) -> GainCalibration:
    """The gain ``gain="auto"`` chooses on these recordings (``gain="auto:HZ"`` for
    ``target_hz``): the CLI's ``--gain auto`` on the same recordings gives the same gain.
    Labels are never read. ``recordings`` takes what :func:`features` takes; with
    ``causal=True`` the gain is calibrated on the causally conditioned signal, as
    ``neurotex train --causal --gain auto`` does. ``stage_options`` are :func:`features`'
    (``preset``, ``cutoff``, ``baseline``, ``whole``, ...).

    Pass the result's ``gain`` to the features of further recordings (a test set) so
    that they are encoded as the calibration recordings were.

    Raises :class:`ParameterError` when no recording has any signal to calibrate on."""
    if "gain" in stage_options:
        raise ParameterError("calibrate_gain chooses the gain; give target_hz instead")
    opts = _stage_options(**stage_options)
    try:
        target = float(target_hz)
    except (TypeError, ValueError):
        raise ParameterError(f"invalid parameter `target_hz`: expected a number, got {target_hz!r}")
    opts["gain"] = f"auto:{target!r}"
    opts["causal"] = bool(causal)
    gain, _ = _calibrate(recordings, opts, fs, mask)
    if gain is None:
        raise InternalError("internal error in neurotex (please report it): no gain calibration")
    return gain


def _raster(spikes: Any) -> np.ndarray:
    a = np.asarray(spikes)
    if a.dtype == bool:
        a = a.astype(np.uint8)
    if a.dtype != np.uint8:
        if a.dtype.kind in "iu" and a.size and (a.min() < 0 or a.max() > 1):
            raise DataError("spikes: a raster holds 0 or 1")
        if a.dtype.kind not in "iu":
            raise DataError(f"spikes must be a uint8 raster (T, rows, cols), got dtype {a.dtype}")
        a = a.astype(np.uint8)
    return a


def spike_stats(spikes: Any, bin_ms: int = _DEFAULTS["bin_ms"]) -> np.ndarray:
    """MSR (Hz), CV_ISI and Fano factor (``bin_ms`` windows) of every cell of a spike
    raster ``(T, rows, cols)`` (as :func:`encode` returns): float64 ``(rows, cols, 3)``."""
    return _native.spike_stats(_raster(spikes), int(bin_ms))


def rate_volume(spikes: Any, bin_ms: Optional[int] = _DEFAULTS["bin_ms"]) -> np.ndarray:
    """Mean rates (Hz) in ``bin_ms`` bins of a spike raster ``(T, rows, cols)``:
    float64 ``(rows, cols, bins)``; a last partial bin is dropped. ``bin_ms=None`` gives
    one bin over the whole raster (the 2D-GLCM's image)."""
    return _native.rate_volume(_raster(spikes), None if bin_ms is None else int(bin_ms))


def _volume(v: Any) -> np.ndarray:
    a = np.asarray(v)
    if a.dtype.kind not in "fiu":
        raise DataError(f"volume must hold real numbers, got dtype {a.dtype}")
    return a.astype(np.float64, copy=False)


def glcm3d(
    volume: Any,
    levels: int = _DEFAULTS["levels"],
    distances: Sequence[int] = _DEFAULTS["distances"],
    symmetric: bool = _DEFAULTS["symmetric"],
    range: Optional[Tuple[float, float]] = None,
    mask: Any = None,
) -> np.ndarray:
    """The mean 3D co-occurrence matrix of a rate volume ``(rows, cols, bins)``, as
    summed counts: uint64 ``(levels, levels)``. The volume is quantised to ``levels``
    gray levels over its own range (or ``range``), and pairs are counted for the 13
    directions of the paper times each distance (coordinates row, col, time)."""
    return _native.glcm(_volume(volume), True, int(levels), [int(d) for d in distances],
                        bool(symmetric), range, _mask_list(mask, "mask"))


def glcm2d(
    image: Any,
    levels: int = _DEFAULTS["levels"],
    distances: Sequence[int] = _DEFAULTS["distances"],
    symmetric: bool = _DEFAULTS["symmetric"],
    range: Optional[Tuple[float, float]] = None,
    mask: Any = None,
) -> np.ndarray:
    """The summed 2D co-occurrence counts of an image ``(rows, cols)`` (such as
    ``rate_volume(spikes, None)[..., 0]``) over the first four directions times each
    distance: uint64 ``(levels, levels)``."""
    return _native.glcm(_volume(image), False, int(levels), [int(d) for d in distances],
                        bool(symmetric), range, _mask_list(mask, "mask"))


def haralick(counts: Any, full: bool = False) -> np.ndarray:
    """Haralick features of a co-occurrence count matrix ``(L, L)`` (non-negative
    integers, as :func:`glcm3d` returns): contrast, correlation, ASM (the paper's), or the
    13 of :data:`HARALICK_FULL_NAMES` with ``full=True``. float64. Raises
    :class:`DataError` for a matrix without pairs (all zeros) or whose counts total 2^55
    or more (beyond the features' exact sums)."""
    a = np.asarray(counts)
    if a.dtype.kind not in "iu":
        raise DataError(f"counts must be non-negative integers, got dtype {a.dtype}")
    if a.size and a.min() < 0:
        raise DataError("counts must be non-negative integers")
    return _native.haralick_features(a.astype(np.uint64, copy=False), bool(full))


def cross_validate(
    X: Any,
    y: Sequence[Any],
    classifier: str = "knn",
    *,
    folds: int = 5,
    seed: int = 0,
    repeats: int = 1,
    **classifier_options: Any,
) -> Dict[str, Any]:
    """Stratified, shuffled ``folds``-fold cross-validation with the library's folds, as
    ``neurotex evaluate`` scores a feature table: the same accuracy for the same rows,
    labels and seed. ``classifier``: ``knn`` (``k``, ``standardize``), ``forest``
    (``trees``, ``max_depth``, ``min_samples_leaf``, ``max_features``, ``bootstrap``,
    ``forest_seed``: ``seed`` is the folds', as the CLI's ``--seed``) or ``linear`` (``c``, ``max_iter``, ``tol``). Returns a dict with
    ``accuracy``, ``accuracy_std``, ``per_repeat``, ``confusion`` and ``labels``."""
    X = np.asarray(X, dtype=np.float64)
    if X.ndim != 2:
        raise DataError(f"X must be (n_samples, n_features), got shape {X.shape}")
    return _native.cross_validate(X, [str(v) for v in y], classifier, classifier_options,
                                  int(folds), int(seed), int(repeats))


def evaluate(
    path: Union[str, os.PathLike],
    *,
    method: Optional[str] = None,
    classifier: Optional[str] = None,
    classifier_options: Optional[Dict[str, Any]] = None,
    folds: Optional[int] = None,
    repeats: Optional[int] = None,
    seed: int = 0,
    speeds: Any = None,
    train_speeds: Any = None,
    test_speeds: Any = None,
    train_where: Optional[str] = None,
    test_where: Optional[str] = None,
    group_by: Optional[str] = None,
    taxel: Optional[str] = None,
    tau_ms: Optional[float] = None,
    encoder_draws: int = 1,
    causal: bool = False,
    **stage_options: Any,
) -> Dict[str, Any]:
    """Evaluates a method and a classifier on the dataset folder ``path`` (sampled
    recordings or address events) by ``neurotex evaluate``'s own workflow: the same
    numbers as ``neurotex evaluate --dataset PATH --json``, as a dict (``accuracy``,
    ``accuracy_interval`` with its 95 % bounds, ``metrics`` with the chance levels,
    ``confusion``, ``classifier``, ``pipeline`` with every stage's parameter as applied
    (stages the method does not use as they stand),
    ``provenance`` with neurotex's build, the dataset's fingerprint and folder and those
    parameters as lines of text, ...).

    ``method`` and ``classifier`` are the CLI's (``None``: glcm3d with KNN; the spiking
    network with ``classifier="snn"`` or ``method="spikes"``), ``classifier_options`` the
    classifier's knobs (``{"k": 3}``, ``{"trees": 500}``, ``{"hidden": 64}``); ``folds``,
    ``repeats`` and ``seed`` the cross-validation's (``None``: the CLI's defaults);
    ``speeds`` keeps only those speeds; ``train_speeds`` with ``test_speeds``, or
    ``train_where`` with ``test_where`` (``"trial=0,1"``), train on one set and test on the
    other instead; ``group_by`` keeps a manifest column's groups within one fold;
    ``taxel`` (``"2,3"``) one taxel for ``method="taxel"``; ``tau_ms`` the van Rossum
    kernel's; ``encoder_draws`` above 1 encodes every recording that many times (as run,
    then with rounding-level perturbations of its input) and adds ``encoder_draws``: each
    encoding's accuracy and their mean with an interval over encodings and recordings.
    Stage options (``gain="auto"``, ``encoding``, ``bin_ms``, ...) are the
    CLI's; what the workflow says goes to the ``neurotex`` logger."""
    opts = _stage_options(**stage_options)
    opts["causal"] = bool(causal)

    def listed(v: Any) -> Optional[List[float]]:
        return None if v is None else [float(x) for x in np.atleast_1d(v)]

    return _native.evaluate_dataset(
        os.fspath(path), method, classifier, dict(classifier_options or {}), opts,
        folds, repeats, int(seed), listed(speeds), listed(train_speeds), listed(test_speeds),
        train_where, test_where, group_by, taxel, tau_ms, int(encoder_draws))


def compare(
    path: Union[str, os.PathLike],
    *,
    encodings: Optional[Sequence[str]] = None,
    methods: Optional[Sequence[str]] = None,
    classifiers: Optional[Sequence[str]] = None,
    speeds: Any = None,
    per: Optional[str] = None,
    hold_out: Optional[str] = None,
    train_where: Optional[str] = None,
    test_where: Optional[str] = None,
    group_by: Optional[str] = None,
    folds: Optional[int] = None,
    repeats: Optional[int] = None,
    seed: int = 0,
    nested: bool = False,
    inner_folds: Optional[int] = None,
    tau_ms: Optional[float] = None,
    knn_options: Optional[Dict[str, Any]] = None,
    snn_options: Optional[Dict[str, Any]] = None,
    out: Optional[Union[str, os.PathLike]] = None,
    causal: bool = False,
    encoder_draws: int = 1,
    **stage_options: Any,
) -> Dict[str, Any]:
    """Compares encodings x feature methods x classifiers on the dataset folder ``path``
    by ``neurotex compare``'s own workflow: the same object as ``neurotex compare
    --dataset PATH --json``, as a dict (each candidate's accuracy with its 95 % interval
    and paired test against the paper's method, chance, and with ``nested=True`` the
    accuracy of choosing the best inside each training set).

    ``encodings``, ``methods`` and ``classifiers`` are lists of the CLI's names (``None``:
    its standard sets); ``per="speed_mm_s"`` cross-validates within each speed,
    ``hold_out="speed_mm_s"`` holds each speed out in turn, ``train_where`` with
    ``test_where`` (``"trial=0,1"``) trains on one set and tests on the other (pooled
    recordings without any); ``group_by``, ``folds``, ``repeats``, ``seed``,
    ``inner_folds`` (with ``nested=True``: the folds of an inner ranking of its own;
    ``None`` holds out each of the other outer folds in turn) and ``tau_ms`` are the
    CLI's. ``knn_options`` (``{"k": 3}``) and ``snn_options`` (``{"hidden": 64}``) are
    the knobs of the KNN and spiking-network candidates. With ``out``, the
    folder also gets compare.json, compare.md and the figures, as ``--out``: a new or
    empty folder, or an earlier output of neurotex, which is replaced whole; any other
    folder is refused before the comparison runs. Stage options (``gain="auto"``,
    ``bin_ms``, ...) are the CLI's. ``encoder_draws`` above 1 encodes every recording
    that many times (as run, then with rounding-level perturbations of its input) and
    gives each candidate that reads spikes ``over_encodings``: its accuracy under each
    encoding, their mean and an interval that draws an encoding as well as the
    recordings (the ranking stays that of the encoding as run), as ``--encoder-draws``."""
    opts = _stage_options(**stage_options)
    opts["causal"] = bool(causal)

    def names(v: Optional[Sequence[str]], what: str) -> Optional[List[str]]:
        if v is None:
            return None
        if isinstance(v, str):
            raise ParameterError(f"{what} must be a list of names, got the string {v!r}")
        return [str(x) for x in v]

    only = None if speeds is None else [float(x) for x in np.atleast_1d(speeds)]
    return _native.compare_dataset(
        os.fspath(path), opts, dict(knn_options or {}), dict(snn_options or {}),
        names(encodings, "encodings"), names(methods, "methods"),
        names(classifiers, "classifiers"), only, per, hold_out, train_where, test_where,
        group_by, folds, repeats, int(seed), bool(nested), inner_folds, tau_ms,
        None if out is None else os.fspath(out), int(encoder_draws))


def load_dataset(path: Union[str, os.PathLike], rows: Optional[Sequence[int]] = None) -> Dataset:
    """Reads a dataset folder (``manifest.csv``, recordings, optional ``layout.toml``) as
    the library reads it: every recording as float64 ``(T, rows, cols)`` on its grid,
    with its label, speed, sliding phase and the layout's rate and mask. ``rows`` reads
    only those manifest rows (0-based), e.g. one shard of a large dataset.

    Raises :class:`NotFoundError` for a missing folder and :class:`DataError` for a bad
    manifest or recording."""
    d = _native.load_dataset(os.fspath(path), None if rows is None else [int(i) for i in rows])
    mask = None
    recs = []
    for a, info, row in zip(d["arrays"], d["infos"], d["rows"]):
        name, fs, present, label, speed, start, end, times = info
        m = None
        if present is not None and not all(present):
            m = np.array(present, dtype=bool).reshape(a.shape[1], a.shape[2])
            mask = m
        recs.append(Recording(
            x=a, fs=fs, label=label, speed=speed,
            slide=None if start is None and end is None else (start, end),
            times=None if times is None else np.array(times), mask=m, name=name,
            meta=dict(row)))
    return Dataset(recordings=recs, rows=list(d["rows"]), columns=list(d["columns"]),
                   fs=d["fs"], baseline=d["baseline"], mask=mask, path=os.fspath(path))


#: tonic's event dtype, as neurotex writes events: ``x`` the grid column, ``y`` the row,
#: ``t`` in microseconds, ``p`` 1 for ON (the SA population's spikes) and 0 for OFF (FA).
EVENT_DTYPE = np.dtype([("x", np.int64), ("y", np.int64), ("t", np.int64), ("p", np.int64)])


def _event_arrays(columns: Any) -> List[np.ndarray]:
    """The native ``(x, y, t, p)`` columns of each recording as :data:`EVENT_DTYPE` arrays."""
    out = []
    for x, y, t, p in columns:
        a = np.empty(len(t), dtype=EVENT_DTYPE)
        a["x"], a["y"], a["t"], a["p"] = x, y, t, p
        out.append(a)
    return out


def events(path: Union[str, os.PathLike], rows: Optional[Sequence[int]] = None, *,
           encoding: str = "sa+fa", **stage_options: Any) -> List[np.ndarray]:
    """The spikes of a dataset folder's recordings as tonic's event arrays
    (:data:`EVENT_DTYPE`: ``x``, ``y``, ``t`` in microseconds, ``p``; in time order), one
    per manifest row (or per row of ``rows``, 0-based). An address-event dataset's events
    are read as every command reads them; a sampled one's recordings are encoded with the
    stage options (``encoding``, ``gain``, ``preset``, ...), the SA population's spikes as
    ON (``p`` 1) and the FA population's as OFF (``p`` 0), as ``neurotex export events``
    writes them. ``encoding`` defaults to ``"sa+fa"``, both polarities (``"sa"``: ON only,
    ``"fa"``: OFF only; a dataset without polarities needs ``"sa"``). These are spikes:
    events in 1 ms steps, at most one per cell, polarity and millisecond, with ``p``
    renumbered 1/0 whatever values the sensor wrote. ``gain="auto"`` and ``causal=True``
    are refused: they calibrate on a whole dataset.

    Raises :class:`NotFoundError` for a missing folder, :class:`DataError` for a bad
    recording and :class:`ParameterError` for a broken option."""
    opts = _stage_options(encoding=encoding, **stage_options)
    if rows is None:
        _, manifest, _ = _native.dataset_events(os.fspath(path), opts, [])
        rows = range(len(manifest))
    columns, _, _ = _native.dataset_events(os.fspath(path), opts, [int(i) for i in rows])
    return _event_arrays(columns)


def save_dataset(
    path: Union[str, os.PathLike],
    recordings: Any,
    labels: Sequence[Any],
    *,
    fs: float = 1000.0,
    speeds: Any = None,
    trials: Any = None,
    forces: Any = None,
    names: Optional[Sequence[str]] = None,
    extra: Optional[Sequence[Dict[str, Any]]] = None,
    mask: Any = None,
) -> None:
    """Writes recordings as a dataset folder the CLI reads: one ``.npy`` each (as given,
    float32 or float64), ``manifest.csv`` (file, label, speed, force, trial, ``extra``
    columns) and ``layout.toml`` (``fs``, mask). Written whole or not at all; the folder
    must not exist or be empty."""
    items = _recording_list(recordings)
    n = len(items)
    if len(labels) != n:
        raise ParameterError(f"{len(labels)} labels for {n} recordings")
    if names is None:
        names = [f"rec_{i:05d}.npy" for i in range(n)]
    items = [r if isinstance(r, Recording) else Recording(x=r, fs=fs) for r in items]
    for r, nm, lab in zip(items, names, labels):
        r.name, r.label = nm, str(lab)
    arrays, infos = _prepare(items, fs, mask, speeds)
    trials = [None if t is None else int(t) for t in (trials if trials is not None else [None] * n)]
    forces = [None if f is None else float(f) for f in (forces if forces is not None else [None] * n)]
    extra = [{str(k): str(v) for k, v in e.items()} for e in (extra or [{}] * n)]
    _native.save_dataset(os.fspath(path), arrays, infos, trials, forces, extra, float(fs))


def simulate(
    out: Optional[Union[str, os.PathLike]] = None,
    *,
    seed: int = 0,
    trials: int = 20,
    speeds: Sequence[float] = (5.0, 10.0, 15.0),
    textures: Optional[Sequence[str]] = None,
) -> Dataset:
    """Simulates the paper's rig (8 textures x ``speeds`` x ``trials``, deterministic for
    ``seed``) as ``neurotex simulate`` does, writes it to ``out`` (a temporary folder when
    ``None``) and returns it loaded: the same bits as the CLI's files."""
    if out is None:
        with tempfile.TemporaryDirectory() as tmp:
            target = os.path.join(tmp, "sim")
            _native.simulate(target, int(seed), int(trials), [float(s) for s in speeds],
                             None if textures is None else list(textures))
            ds = load_dataset(target)
            ds.path = None
            return ds
    _native.simulate(os.fspath(out), int(seed), int(trials), [float(s) for s in speeds],
                     None if textures is None else list(textures))
    return load_dataset(out)


def _fingerprint(arrays: Sequence[np.ndarray], labels: Sequence[str]) -> str:
    h = hashlib.sha256()
    for a, l in zip(arrays, labels):
        h.update(str(a.shape).encode())
        h.update(np.ascontiguousarray(a, dtype=np.float64).tobytes())
        h.update(l.encode())
    return "python-arrays-sha256:" + h.hexdigest()


class _Predicting:
    """What both kinds of model share: prediction on recordings encoded with the model's own
    pipeline, and the class order."""

    _native: Any

    def predict(self, recordings: Any, *, fs: float = 1000.0, mask: Any = None) -> np.ndarray:
        """The predicted label of each recording (encoded with the model's own pipeline)."""
        return self._predict(recordings, fs, mask)[0]

    def predict_proba(self, recordings: Any, *, fs: float = 1000.0, mask: Any = None) -> np.ndarray:
        """Each class's share (columns in :attr:`classes_` order): KNN's votes, the
        forest's mean leaf shares, the logistic regression's probabilities, the softmax of
        a spiking network's scores."""
        return self._predict(recordings, fs, mask)[1]

    def _predict(self, recordings: Any, fs: float, mask: Any) -> Tuple[np.ndarray, np.ndarray]:
        folder = _folder(recordings)
        if folder is not None:
            labels, shares = self._native.predict_dataset(folder)
            return np.array(labels, dtype=object), shares
        items = _recording_list(recordings)
        arrays, infos = _prepare(items, fs, mask)
        labels, shares = self._native.predict(arrays, infos)
        return np.array(labels, dtype=object), shares

    @property
    def classes_(self) -> List[str]:
        """The classes, in the order of :meth:`predict_proba`'s columns."""
        return list(self._native.labels)


def _folder(recordings: Any) -> Optional[str]:
    """The dataset folder ``recordings`` names (a path to a folder), or ``None``."""
    if isinstance(recordings, (str, os.PathLike)) and os.path.isdir(recordings):
        return os.fspath(recordings)
    if isinstance(recordings, (str, os.PathLike)):
        raise NotFoundError(f"{os.fspath(recordings)}: no such dataset folder")
    return None


def _training_set(recordings: Any, labels: Optional[Sequence[Any]], fs: float, mask: Any,
                  speeds: Any) -> Tuple[Any, Any, str, Optional[str]]:
    """The training recordings as arrays and infos, their fingerprint and baseline, with
    ``labels`` (when given) replacing the recordings' own."""
    baseline = recordings.baseline if isinstance(recordings, Dataset) else None
    items = _recording_list(recordings)
    if labels is not None:
        if len(labels) != len(items):
            raise ParameterError(f"{len(labels)} labels for {len(items)} recordings")
        items = [r if isinstance(r, Recording) else Recording(x=r, fs=fs) for r in items]
        items = [Recording(**{**r.__dict__, "label": str(l)}) for r, l in zip(items, labels)]
    arrays, infos = _prepare(items, fs, mask, speeds)
    return arrays, infos, _fingerprint(arrays, [i[3] for i in infos]), baseline


class Model(_Predicting):
    """A trained classifier with its pipeline: the model file of ``neurotex train``
    (read with :meth:`load`, written with :meth:`save`, which the CLI reads back). Every
    classifier's model is a :class:`Model`: a spiking network's is the subclass
    :class:`SpikingModel`, which :meth:`train` and :meth:`load` return for it."""

    def __init__(self, native: Any) -> None:
        self._native = native

    @classmethod
    def load(cls, path: Union[str, os.PathLike]) -> "Model":
        """Reads a model file of any classifier (a spiking network's model file or NIR
        graph gives a :class:`SpikingModel`). Raises :class:`NotFoundError` or
        :class:`ModelError`."""
        if cls is Model and _native.is_spiking_model(os.fspath(path)):
            return SpikingModel.load(path)
        return cls(_native.NativeModel.load(os.fspath(path)))

    def save(self, path: Union[str, os.PathLike]) -> None:
        """Writes the model file (whole or not at all)."""
        self._native.save(os.fspath(path))

    @classmethod
    def train(
        cls,
        recordings: Any,
        labels: Optional[Sequence[Any]] = None,
        method: Optional[str] = None,
        classifier: Optional[str] = None,
        *,
        fs: float = 1000.0,
        mask: Any = None,
        speeds: Any = None,
        taxel: Optional[str] = None,
        classifier_options: Optional[Dict[str, Any]] = None,
        causal: bool = _DEFAULTS["causal"],
        **stage_options: Any,
    ) -> "Model":
        """Trains ``classifier`` (``knn``, the default, ``forest``, ``linear`` or ``snn``;
        knobs in ``classifier_options``, e.g. ``{"k": 5}``, or the keywords of
        :meth:`SpikingModel.train` for ``snn``) on ``method``'s features of the recordings
        (``glcm3d`` by default), as ``neurotex train`` does. As there, ``classifier="snn"``
        reads the spike trains (``method="spikes"``) and ``method="spikes"`` is read by the
        spiking network: either one trains it and returns a :class:`SpikingModel`.
        ``labels`` default to the recordings' own (a :class:`Dataset`'s). ``stage_options``
        are :func:`features`' (gain, cutoff, levels, ...).

        ``recordings`` may be a dataset folder's path, sampled or of address events: the
        model is then trained by ``neurotex train --dataset``'s own workflow (the CLI's
        model file, byte for byte), with ``speeds`` the speeds to train on (``--speeds``;
        all when ``None``) and the labels the manifest's.

        ``causal=True`` trains a causal model (``neurotex train --causal``): a forward-only
        low-pass, and each taxel's resting value and one normalisation scale fixed on
        these recordings (labels unused) and stored in the model, so that
        :class:`StreamClassifier` can classify a live stream with it. ``gain="auto"``
        calibrates the gain on these recordings (after the causal conditioning, when
        both); the model keeps the calibration (:attr:`gain_calibration`)."""
        if classifier is None:
            classifier = "snn" if method == "spikes" else "knn"
        if method is None:
            method = "spikes" if classifier == "snn" else "glcm3d"
        if (method == "spikes") != (classifier == "snn"):
            raise ParameterError(
                "invalid parameter `classifier`: van-rossum classifies with knn, spikes with "
                "snn (the spiking network), and the feature methods with knn, forest or "
                f"linear, got {classifier} with the {method} method")
        folder = _folder(recordings)
        if folder is not None:
            return _train_folder(folder, labels, method, classifier, classifier_options,
                                 taxel, speeds, causal, stage_options)
        if method == "spikes":
            if taxel is not None:
                raise ParameterError("taxel applies to method='taxel' only")
            knobs = _native.classifier_knobs("snn")
            for name in classifier_options or {}:
                if name not in knobs:
                    raise ParameterError(
                        f"unknown option `{name}` for the spiking network; its options are "
                        + ", ".join(knobs))
            return SpikingModel.train(recordings, labels, fs=fs, mask=mask, speeds=speeds,
                                      causal=causal, **dict(classifier_options or {}),
                                      **stage_options)
        arrays, infos, fp, baseline = _training_set(recordings, labels, fs, mask, speeds)
        opts = _stage_options(**stage_options)
        opts["causal"] = bool(causal)
        native = _native.train_model(arrays, infos, method, opts, classifier,
                                     dict(classifier_options or {}), fp, baseline, taxel)
        model = cls(native)
        for c in (model.causal, model.gain_calibration):
            if c is not None:
                _log.info("%s", c)
        return model

    @property
    def method(self) -> str:
        """The feature method."""
        return self._native.method

    @property
    def columns(self) -> List[str]:
        """The feature columns the classifier uses."""
        return list(self._native.columns)

    @property
    def gain(self) -> float:
        """The encoder's gain."""
        return self._native.gain

    @property
    def fingerprint(self) -> str:
        """The training data's fingerprint."""
        return self._native.fingerprint

    @property
    def gain_calibration(self) -> Optional[GainCalibration]:
        """How ``gain="auto"`` chose :attr:`gain` on the training recordings; ``None`` for
        a gain given as a number."""
        return GainCalibration._from_dict(self._native.gain_calibration)

    @property
    def causal(self) -> Optional[CausalConditioning]:
        """The causal conditioning of a model trained with ``causal=True`` (or
        ``neurotex train --causal``): what :class:`StreamClassifier` needs; ``None`` for
        the paper's offline pipeline."""
        c = CausalConditioning._from_dict(self._native.causal)
        if c is None:
            return None
        return CausalConditioning(c.offsets, c.scale, None, self._native.median_duration_ms)

    def __repr__(self) -> str:
        return (f"Model({self._native.classifier}, method={self.method!r}, "
                f"classes={len(self.classes_)}, trained on {self._native.n_training})")




def _train_folder(folder: str, labels: Any, method: Optional[str], classifier: Optional[str],
                  classifier_options: Any, taxel: Optional[str], speeds: Any, causal: bool,
                  stage_options: Dict[str, Any]) -> "Model":
    """A model trained on a dataset folder by ``neurotex train``'s own workflow: the CLI's
    model file, byte for byte, for sampled recordings and address events alike."""
    if labels is not None:
        raise ParameterError("labels: a dataset folder's labels are its manifest's")
    opts = _stage_options(**stage_options)
    opts["causal"] = bool(causal)
    only = None if speeds is None else [float(v) for v in np.atleast_1d(speeds)]
    native, log = _native.train_dataset(folder, method, classifier,
                                        dict(classifier_options or {}), opts, only, taxel)
    if log is None:
        return Model(native)
    ran, best, loss = log
    return SpikingModel(native, {"epochs": ran, "best_epoch": best, "validation_loss": loss})


def _nir() -> Any:
    """The ``nir`` package, or an error that says how to get it."""
    try:
        import nir
    except ImportError as e:
        raise ImportError("NIR graphs as objects need the `nir` package: pip install nir "
                          "(files need nothing: save_nir, SpikingModel.load)") from e
    return nir


class SpikingModel(Model):
    """A trained spiking network with its pipeline: the model file of ``neurotex train
    --classifier snn`` (``Model.train(..., classifier="snn")``), or a NIR graph (:meth:`to_nir`, :meth:`from_nir`; see
    docs/spiking-classifier.md). Its input is the recordings' spikes, encoded with the
    model's own pipeline; its shares are the softmax of the readout's scores."""

    def __init__(self, native: Any, training: Optional[Dict[str, Any]] = None) -> None:
        super().__init__(native)
        #: How training went (``epochs``, ``best_epoch``, ``validation_loss``) for a model
        #: trained by :meth:`train`; ``None`` for one read from a file.
        self.training = training

    @classmethod
    def train(
        cls,
        recordings: Any,
        labels: Optional[Sequence[Any]] = None,
        *,
        fs: float = 1000.0,
        mask: Any = None,
        speeds: Any = None,
        hidden: int = _SNN_DEFAULTS["hidden"],
        dt_ms: int = _SNN_DEFAULTS["dt_ms"],
        epochs: int = _SNN_DEFAULTS["epochs"],
        readout: str = _SNN_DEFAULTS["readout"],
        seed: int = _SNN_DEFAULTS["seed"],
        recurrent: bool = _SNN_DEFAULTS["recurrent"],
        reset: Optional[str] = None,
        target: str = _SNN_DEFAULTS["target"],
        tau_syn_ms: float = _SNN_DEFAULTS["tau_syn_ms"],
        tau_mem_ms: float = _SNN_DEFAULTS["tau_mem_ms"],
        tau_out_ms: float = _SNN_DEFAULTS["tau_out_ms"],
        window_ms: Optional[int] = _SNN_DEFAULTS["window_ms"],
        train_decays: bool = _SNN_DEFAULTS["train_decays"],
        travel: Union[str, float] = _SNN_DEFAULTS["travel"],
        warp: Optional[float] = _SNN_DEFAULTS["warp"],
        adapt_ms: Optional[float] = _SNN_DEFAULTS["adapt_ms"],
        adapt_strength: float = _SNN_DEFAULTS["adapt_strength"],
        delay_ms: Optional[float] = _SNN_DEFAULTS["delay_ms"],
        causal: bool = _DEFAULTS["causal"],
        **stage_options: Any,
    ) -> "SpikingModel":
        """Trains a spiking network on the recordings' spike trains, as ``neurotex train
        --classifier snn`` does: ``hidden`` LIF neurons, time steps of ``dt_ms``, at most
        ``epochs`` passes with early stopping on 20 % of each class, scores read as the
        readout's ``mean`` or ``max`` over time, weights seeded by ``seed`` (the same on
        any number of threads); ``recurrent=True`` connects the hidden layer to itself
        (``--snn-recurrent``); ``reset`` is how a hidden neuron resets on a spike:
        ``"zero"`` (one spike per step at most) or ``"subtract"`` (n = floor(v) spikes,
        v - n kept: the neuron of sinabs, Rockpool and Xylo, needed to export to them;
        ``--snn-reset``; default ``"zero"``, ``"subtract"`` with Xylo); ``target`` is where
        the network runs: ``"float"`` or ``"xylo"`` (trained within Xylo Audio 2's limits,
        predicting in the chip's integers; ``--snn-target``); ``tau_syn_ms``, ``tau_mem_ms``
        and ``tau_out_ms`` are the hidden neurons' synaptic and membrane time constants and
        the readout's (``--snn-tau-*-ms``; moved to the chip's decays with Xylo);
        ``window_ms`` trains on windows of that many ms drawn anew at each epoch from
        anywhere in each recording (``--snn-window-ms``; ``None``: whole recordings);
        ``train_decays=True`` trains each hidden neuron's synaptic and membrane decays
        beside the weights (``--snn-train-decays``); ``travel`` is how the network counts
        time (``--snn-travel``): ``"median"`` in steps of travel at the training recordings'
        median speed (``speeds``; in ms without them), a speed in mm/s for that reference,
        or ``"off"`` (the default) for ms; ``warp`` trains on time-warped recordings, each
        stretched or squeezed at every epoch by a factor drawn log-uniformly between
        ``1/warp`` and ``warp`` (``--snn-warp``; ``None``: as they are); ``adapt_ms``
        gives the hidden neurons adaptive thresholds (ALIF) that rise by ``adapt_strength``
        times their spike rate over about ``adapt_ms`` ms (``--snn-adapt-ms``,
        ``--snn-adapt-strength``; ``None``: fixed thresholds; such a network has no NIR
        graph); ``delay_ms`` gives each input synapse a delay of up to that many ms, trained
        beside its weight (``--snn-delay-ms``; ``None``: no delays; no NIR graph either).
        ``labels`` and ``stage_options`` (``encoding``, ``gain``, ...) as
        :meth:`Model.train`; ``causal=True`` trains for :class:`StreamClassifier`."""
        snn = {"hidden": hidden, "dt_ms": dt_ms, "epochs": epochs, "readout": readout,
               "seed": seed, "recurrent": recurrent, "target": target,
               "tau_syn_ms": tau_syn_ms, "tau_mem_ms": tau_mem_ms, "tau_out_ms": tau_out_ms,
               "window_ms": window_ms, "train_decays": train_decays, "travel": str(travel),
               "warp": warp, "adapt_ms": adapt_ms, "adapt_strength": adapt_strength,
               "delay_ms": delay_ms}
        if reset is not None:
            snn["reset"] = reset
        folder = _folder(recordings)
        if folder is not None:
            model = _train_folder(folder, labels, "spikes", "snn", snn, None, speeds, causal,
                                  stage_options)
            assert isinstance(model, SpikingModel)
            return model
        arrays, infos, fp, baseline = _training_set(recordings, labels, fs, mask, speeds)
        opts = _stage_options(**stage_options)
        opts["causal"] = bool(causal)
        native, ran, best, loss = _native.train_spiking_model(arrays, infos, opts, snn, fp,
                                                              baseline)
        return cls(native, {"epochs": ran, "best_epoch": best, "validation_loss": loss})

    @classmethod
    def load(cls, path: Union[str, os.PathLike]) -> "SpikingModel":
        """Reads a spiking model file, or a NIR graph written by neurotex."""
        return cls(_native.NativeSpikingModel.load(os.fspath(path)))

    @property
    def method(self) -> str:
        """``spikes``: the network reads the spike trains themselves."""
        return "spikes"

    @property
    def columns(self) -> List[str]:
        """No feature column: the network reads spike inputs (one per taxel and
        population)."""
        return []


    def save(self, path: Union[str, os.PathLike]) -> None:
        """Writes the model file (whole or not at all)."""
        self._native.save(os.fspath(path))

    def to_nir(self, for_tool: str = "nir") -> Any:
        """The network as a ``nir.NIRGraph`` (needs the ``nir`` package) written for
        ``for_tool``, as ``neurotex export nir --for``: ``"nir"`` (Input, Affine, CubaLIF,
        Affine, a CubaLIF readout that never fires, Output; NIR's equations by forward
        Euler with ``dt`` in seconds, and the pipeline, in its metadata; Norse reads it),
        ``"snntorch"`` (the same, its constants scaled to snnTorch's 0.1 ms step),
        ``"norse"``, or ``"sinabs"`` / ``"rockpool"`` (networks trained with
        ``snn_reset="subtract"``)."""
        import tempfile

        nir = _nir()

        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "model.nir")
            self._native.write_nir(path, for_tool)
            return nir.read(path)

    def save_nir(self, path: Union[str, os.PathLike], for_tool: str = "nir") -> None:
        """Writes the network as a NIR file (as ``neurotex export nir --for FOR_TOOL``)."""
        self._native.write_nir(os.fspath(path), for_tool)

    @classmethod
    def from_nir(cls, graph: Any, like: Optional["SpikingModel"] = None) -> "SpikingModel":
        """A model from a NIR graph (a ``nir.NIRGraph`` or a path to a ``.nir`` file). A
        graph that does not carry neurotex's metadata (trained in snnTorch, Norse,
        Rockpool on :func:`neurotex export inputs` tensors) takes its pipeline, grid and
        labels from ``like``."""
        native_like = like._native if like is not None else None
        if isinstance(graph, (str, os.PathLike)):
            return cls(_native.NativeSpikingModel.from_nir(os.fspath(graph), native_like))
        import tempfile

        nir = _nir()

        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "model.nir")
            nir.write(path, graph)
            return cls(_native.NativeSpikingModel.from_nir(path, native_like))

    def __repr__(self) -> str:
        inputs, hidden, classes, dt = self._native.shape
        return f"SpikingModel({inputs} inputs, {hidden} LIF neurons, {classes} classes, dt {dt} ms)"


@dataclass
class Reproduction:
    """What :func:`reproduce` ran and wrote.

    ``report``: the path of ``report.md`` (``results.json`` and ``figures/`` beside it,
    each figure as SVG and PNG); ``results``: ``results.json`` as a dict (every analysis:
    ``e1`` .. ``e9``, ``encoder_sensitivity``, ``taxels``, ``provenance``, ...); ``claims``: the paper's claims
    judged on these results, each a dict with ``statement``, ``verdict`` (``holds``,
    ``not_shown``, ``contradicted``, ``point_agrees``, ``point_disagrees``, ``not_judged``), ``holds``
    and ``detail``; ``headline``: E1 by speed in mm/s, each a dict of accuracies
    (``glcm3d``, ``taxel_mean``, ``taxel_best``, ``chance``, ``majority``, ``n``);
    ``gain_calibration``: what ``gain="auto"`` chose; ``predictions``: the headline
    3D-GLCM evaluations' out-of-fold predictions (the CLI's ``--predictions`` rows, as
    dicts); ``seconds``: the run's wall-clock time."""

    report: str
    results: Dict[str, Any]
    claims: List[Dict[str, Any]]
    headline: Dict[float, Dict[str, Any]]
    gain_calibration: Optional[GainCalibration]
    predictions: List[Dict[str, Any]]
    seconds: float

    @property
    def out_dir(self) -> str:
        """The folder holding the report, ``results.json`` and ``figures/``."""
        return os.path.dirname(self.report)


_HOLDS = ("holds", "point_agrees")
_HEADLINE = ("glcm3d", "taxel_mean", "taxel_best", "chance", "majority", "n")


def reproduce(
    out_dir: Union[str, os.PathLike],
    *,
    dataset: Optional[Union[str, os.PathLike]] = None,
    quick: bool = False,
    seed: int = 0,
    trials: Optional[int] = None,
    seeds: Optional[int] = None,
    k: int = 5,
    standardize: bool = True,
    folds: Optional[int] = None,
    repeats: Optional[int] = None,
    group_by: Optional[str] = None,
    encoder_draws: Optional[int] = None,
    snn: bool = False,
    **stage_options: Any,
) -> Reproduction:
    """Runs the paper's analyses (E0-E9: accuracy per speed, confusion, spatial
    perturbation, temporal information, time to recognition offline and causal, speed
    invariance, gain sweep, neighbours, the standard candidates) as ``neurotex reproduce``
    does with the same options, writes ``report.md``, ``results.json`` and
    ``figures/*.svg`` and ``*.png`` into ``out_dir`` (whole or not at all; an existing folder's files are
    replaced) and returns a :class:`Reproduction`.

    Without ``dataset`` the built-in simulator generates the paper's design in memory
    (8 textures x 5, 10, 15 mm/s x ``trials`` trials, default 20, or 10 with ``quick``),
    ``seeds`` independent datasets from simulation seeds ``seed``, ``seed + 1``, ...
    (default 5, or 1 with ``quick``); ``dataset`` names a dataset folder instead, whose
    manifest must give each recording's speed. ``quick``: fewer CV repeats, perturbation
    counts, fractions and gains (the CI run). ``seed`` also seeds the CV shuffles and the
    perturbations. ``k``, ``standardize``: the KNN. ``folds``, ``repeats``: every
    cross-validation's folds (default 5; a small pilot needs fewer, as each class needs
    that many recordings at each speed) and shuffles (default 10, or 2 with ``quick``).
    ``group_by``: keep each group of this
    manifest column in one fold. ``encoder_draws``: encodings of every recording behind
    the accuracies of E1, E4, E6 and E8 (as run, then with independent rounding-level
    input perturbations; their intervals resample encodings as well as recordings;
    default 8, 1 for the input as run only). ``snn``: E9 also runs the spiking network
    (SA+FA spikes, its default hyperparameters) beside the paper's method on the same
    folds (minutes more). ``stage_options`` are :func:`features`' (``gain``, also
    ``"auto"``, ``preset``, ``cutoff``, ``levels``, ...).

    The run takes minutes (the full paper-scale run with 5 seeds much longer) with the GIL
    released; it cannot be interrupted from Python before it ends.

    A design too small for ``folds`` or ``k`` does not stop the run: the analyses resting
    on the cross-validation within each speed are skipped (``results["skipped"]`` says
    why) and a :class:`UserWarning` says so, as one does when most taxels are silent or at
    the encoder's ceiling.

    Raises :class:`ParameterError` for a broken option, :class:`NotFoundError` for a
    missing dataset folder, :class:`DataError` for recordings the analyses cannot use."""
    out = os.fspath(out_dir)
    opts = _stage_options(**stage_options)
    given = {"dataset": None if dataset is None else os.fspath(dataset), "quick": quick,
             "seed": seed, "trials": trials, "seeds": seeds, "k": k,
             "standardize": standardize, "folds": folds, "repeats": repeats,
             "group_by": group_by, "encoder_draws": encoder_draws, "snn": snn}
    defaults = {"quick": False, "seed": 0, "k": 5, "standardize": True, "snn": False}
    shown = [repr(out)] + [f"{key}={v!r}" for key, v in given.items()
                           if v is not None and defaults.get(key) != v]
    shown += [f"{key}={v!r}" for key, v in stage_options.items()]
    command = f"neurotex.reproduce({', '.join(shown)})  # Python {__version__}"
    results, claims, predictions, seconds = _native.reproduce(
        out, opts, given["dataset"], bool(quick), int(seed),
        None if trials is None else int(trials), None if seeds is None else int(seeds),
        int(k), bool(standardize), group_by,
        None if encoder_draws is None else int(encoder_draws), command,
        None if folds is None else int(folds), None if repeats is None else int(repeats),
        bool(snn))
    claims = [dict(c, holds=c["verdict"] in _HOLDS) for c in claims]
    headline = {float(speed): {key: e[key] for key in _HEADLINE}
                for speed, e in results.get("e1", {}).items()}
    gain = results.get("gain_calibration")
    fields = ("speed_mm_s", "method", "file", "label", "predicted", "fold", "repeat")
    return Reproduction(
        report=os.path.join(out, "report.md"),
        results=results,
        claims=claims,
        headline=headline,
        gain_calibration=None if gain is None else GainCalibration._from_dict(gain),
        predictions=[dict(zip(fields, row)) for row in predictions],
        seconds=seconds,
    )



@dataclass
class Inspection:
    """What :func:`inspect` found. ``findings``: each a dict with ``severity``
    (``severe``, ``warning`` or ``note``), ``area`` (``design``, ``layout``, ``signals``,
    ``encoder``), ``code`` (a stable name such as ``grid-not-filled``), ``message`` and
    ``suggestion`` (the option first); ``design``, ``layout``, ``signals``, ``encoder``:
    the numbers behind them, as ``inspect.json`` holds them; ``text``: the lines the CLI
    prints; ``out_dir``: where ``inspect.md``, ``inspect.json`` and ``figures/`` were
    written, if anywhere."""

    findings: List[Dict[str, Any]]
    design: Dict[str, Any]
    layout: Dict[str, Any]
    signals: Dict[str, Any]
    encoder: Optional[Dict[str, Any]]
    text: List[str]
    out_dir: Optional[str] = None

    @property
    def severe(self) -> List[Dict[str, Any]]:
        """The severe findings: an analysis will fail or mislead unless they are addressed."""
        return [f for f in self.findings if f["severity"] == "severe"]

    def __str__(self) -> str:
        return "\n".join(self.text)


def inspect(
    paths: Union[str, os.PathLike, Sequence[Union[str, os.PathLike]]],
    *,
    out: Optional[Union[str, os.PathLike]] = None,
    encoder: bool = True,
    folds: int = 5,
    k: int = 5,
    name_pattern: Optional[str] = None,
    time_column: Optional[Union[str, int]] = None,
    time_unit: Optional[str] = None,
    channels: Optional[str] = None,
    grid: Optional[str] = None,
    channel_map: Optional[str] = None,
    drop_channels: Optional[str] = None,
    fs: Optional[float] = None,
    header: Optional[bool] = None,
    delimiter: Optional[str] = None,
    duplicate_stamps: Optional[str] = None,
    max_gap_s: Optional[float] = None,
    **stage_options: Any,
) -> Inspection:
    """Checks a dataset folder, or raw CSV logs (files or folders) read as ``neurotex
    import csv`` would read them, before any analysis, as ``neurotex inspect`` does: the
    design (recordings per class and speed, chance, what the folds and ``k`` need), the
    signals (rate, jitter, gaps, resting offsets, dead, clipped and copied channels, a clock
    read as a channel), the layout, and, with ``encoder``, the encoder at the gain (silent
    and saturated taxels, the gain ``gain="auto"`` would choose). Read-only; ``out`` also
    writes ``inspect.md``, ``inspect.json`` and ``figures/`` there.

    The reading options (``name_pattern``, ``time_column``, ``channels``, ``grid`` such as
    ``"3x3"``, ``channel_map``, ``drop_channels`` (channels left out after placing every
    channel on the grid, their cells masked), ``fs``, ``header``, ``delimiter``, ...) are the import's and
    apply to raw logs only; ``stage_options`` are :func:`features`' (``gain``, ``baseline``,
    ``bin_ms``, ...).

    Raises :class:`ParameterError` for a broken option (or reading options given with a
    dataset folder), :class:`NotFoundError` for a missing path."""
    if isinstance(paths, (str, os.PathLike)):
        paths = [paths]
    reading = {"name_pattern": name_pattern, "time_column": time_column,
               "time_unit": time_unit, "channels": channels, "grid": grid,
               "channel_map": channel_map, "drop_channels": drop_channels,
               "fs": fs, "header": header,
               "delimiter": delimiter, "duplicate_stamps": duplicate_stamps,
               "max_gap_s": max_gap_s}
    found, text = _native.inspect(
        [os.fspath(p) for p in paths], _stage_options(**stage_options), reading,
        None if out is None else os.fspath(out), bool(encoder), int(folds), int(k))
    return Inspection(findings=found["findings"], design=found["design"],
                      layout=found["layout"], signals=found["signals"],
                      encoder=found.get("encoder"), text=list(text),
                      out_dir=None if out is None else os.fspath(out))


class StreamClassifier:
    """A causal model (``neurotex train --causal``: a :class:`Model`, or a
    :class:`SpikingModel` whose network runs step by step on the spikes as they come)
    classifying a live stream frame by frame, as ``neurotex stream`` does: ``push`` one frame (one value per taxel, in
    row-major order of the model's taxels) and get ``None``, or the list of what it
    completed: a dict per bin boundary (``t_s``, ``label``, ``scores``, ``decided``,
    ``decision``) and one per episode's end (``end``, ``label``, ``decided_at_s``, ...).
    A bad frame (wrong length, NaN, a stamp beyond 2^33 s, a stamp not after the last or
    more than ``max_gap_s`` after it) raises :class:`DataError` and is skipped; the stream
    goes on. When the next frame follows such a stamp instead of the last good one, the
    clock has jumped: the episode ends (``"ended_by": "gap"``) and a new one starts at that
    frame, as in ``neurotex stream``. ``max_gap_s`` is at most 10 s.

    ``time_unit`` (``"s"``, ``"ms"`` or ``"us"``) is the unit of every stamp pushed: give
    stamps in the unit they were logged in. Stamps are taken relative to the episode's first
    in that unit and only then become seconds, so integer ms stamps on the encoder's 1 ms
    grid give the same spikes as the same frames unstamped at 1 kHz; the same stamps as
    seconds (``0.001 * k``, not exact in binary) can move a near-threshold spike.

    With ``events=True`` the stream takes an event sensor's address events instead
    (``push_event``, ``push_events``), as ``neurotex stream --format events`` does: any model
    (one trained on an event dataset, or a causal or offline one on samples) classifies
    them without its encoder, ON events as SA spikes and OFF as FA. ``origin`` is
    ``"zero"`` (the first episode counts from time 0) or ``"first"`` (from its first event);
    by default the model's event dataset's, else ``"first"``."""

    def __init__(self, model: Union["Model", "SpikingModel", str, os.PathLike], *,
                 window_s: Optional[float] = None,
                 decide: float = 0.8, decide_bins: int = 3, episode: str = "whole",
                 fs: float = 1000.0, max_gap_s: float = 1.0,
                 speed: Optional[float] = None, time_unit: str = "s",
                 events: bool = False, origin: Optional[str] = None) -> None:
        if not isinstance(model, (Model, SpikingModel)):
            spiking = _native.is_spiking_model(os.fspath(model))
            model = (SpikingModel if spiking else Model).load(model)
        self.model = model
        self._native = _native.NativeStream(model._native, window_s, decide, decide_bins,
                                            episode, fs, max_gap_s, speed, time_unit,
                                            events, origin)

    def push_event(self, t: Union[int, float], x: Optional[int] = None,
                   y: Optional[int] = None, p: Optional[int] = None
                   ) -> Optional[List[Dict[str, Any]]]:
        """Takes one event at ``t`` (``time_unit``; an int is exact) of cell ``x``, ``y``
        (or taxel ``x``) with polarity ``p``, or a tick (time has come, no event) when
        ``x`` is None. A bad event raises :class:`DataError` and is skipped."""
        return self._events(self._native.push_event(t, x, y, p))

    def push_events(self, events: Any) -> Optional[List[Dict[str, Any]]]:
        """Takes a structured array of events with fields ``t``, ``x``, ``y`` and
        optionally ``p`` (tonic's, :data:`EVENT_DTYPE`), in time order; the lines they
        completed. Bad events raise :class:`DataError` at the first, the ones before it
        taken."""
        events = np.asarray(events)
        names = events.dtype.names or ()
        missing = [f for f in ("t", "x", "y") if f not in names]
        if missing or events.ndim != 1:
            raise ParameterError(
                f"push_events(events): a 1-D structured array of events is needed, with "
                f"fields t, x, y and optionally p (tonic's dtype, neurotex.EVENT_DTYPE = "
                f"{EVENT_DTYPE}); got dtype {events.dtype} of shape {events.shape}"
                + (f", without field(s) {', '.join(missing)}" if names else ""))
        p = events["p"].astype(np.int64).tolist() if "p" in names else [None] * len(events)
        lines: List[Dict[str, Any]] = []
        for t, x, y, pol in zip(events["t"].tolist(), events["x"].tolist(),
                                events["y"].tolist(), p):
            lines.extend(self._native.push_event(t, x, y, pol))
        return self._events(lines)

    @staticmethod
    def _events(lines: List[Dict[str, Any]]) -> Optional[List[Dict[str, Any]]]:
        return lines or None

    def push(self, frame: Any, t: Optional[float] = None) -> Optional[List[Dict[str, Any]]]:
        """Takes one frame, with its time stamp in ``time_unit`` (or none, at ``fs``)."""
        values = np.asarray(frame, dtype=np.float64).ravel().tolist()
        return self._events(self._native.push(values, t))

    def reset(self) -> Optional[List[Dict[str, Any]]]:
        """Ends the current episode (its summary)."""
        return self._events(self._native.reset())

    def finish(self) -> Optional[List[Dict[str, Any]]]:
        """Ends the stream (the last bins and the summary)."""
        return self._events(self._native.finish())

    @property
    def bad_frames(self) -> int:
        """Frames skipped as bad."""
        return self._native.bad_frames

__all__ = [
    "encode", "features", "spike_stats", "rate_volume", "glcm3d", "glcm2d", "haralick",
    "cross_validate", "evaluate", "compare", "load_dataset", "save_dataset", "simulate", "events", "EVENT_DTYPE", "Model", "SpikingModel", "Recording",
    "StreamClassifier", "reproduce", "Reproduction", "calibrate_gain", "GainCalibration",
    "CausalConditioning", "FeatureTable", "inspect", "Inspection",
    "Dataset", "HARALICK_NAMES", "HARALICK_FULL_NAMES", "METHODS", "Error",
    "ParameterError", "DataError", "NotFoundError", "ReadWriteError", "ModelError",
    "ClassifyError", "InternalError", "benchmark", "datasets",
]

from . import datasets  # noqa: E402  (it imports load_dataset from here)
from .datasets import benchmark  # noqa: E402
