"""scikit-learn estimators over neurotex: a transformer from recordings to features
(:class:`SpikeFeatures`), the library's classifiers of features (:class:`KNNClassifier`,
:class:`RandomForestClassifier`, :class:`LogisticRegression`) and a spiking network that
classifies the recordings' spike trains themselves (:class:`SpikingClassifier`). They follow scikit-learn's
conventions (``get_params``/``set_params``, ``clone``, ``Pipeline``, ``GridSearchCV``)::

    from sklearn.pipeline import make_pipeline
    from sklearn.model_selection import cross_val_score
    from neurotex.sklearn import SpikeFeatures, KNNClassifier

    pipe = make_pipeline(SpikeFeatures(method="glcm3d"), KNNClassifier(k=5))
    cross_val_score(pipe, dataset.recordings, dataset.labels, cv=5)
"""

from __future__ import annotations

from typing import Any, Dict, List, Optional, Sequence, Union

import numpy as np
from sklearn.base import BaseEstimator, ClassifierMixin, TransformerMixin
from sklearn.utils.validation import check_is_fitted, validate_data

from . import _native, features as _features

# Every stage option's default, from the library's one definition of the options.
_DEFAULTS: Dict[str, Any] = _native.stage_defaults()
# Each classifier's defaults, from the library's one definition of its knobs.
_KNN = _native.classifier_defaults("knn")
_FOREST = _native.classifier_defaults("forest")
_LINEAR = _native.classifier_defaults("linear")
_SNN_DEFAULTS: Dict[str, Any] = _native.classifier_defaults("snn")

__all__ = [
    "SpikeFeatures", "KNNClassifier", "RandomForestClassifier", "LogisticRegression",
    "SpikingClassifier",
]


class SpikeFeatures(TransformerMixin, BaseEstimator):
    """Recordings to spike features, as :func:`neurotex.features` computes them.

    ``X`` is a list of arrays ``(T, rows, cols)``, a 4-D array ``(n, T, rows, cols)`` or
    a list of :class:`neurotex.Recording` (``Dataset.recordings``, which keep each
    recording's sliding phase). With a gain given as a number the transformer learns
    nothing (every parameter is the pipeline's, the paper's defaults), so ``fit`` only
    checks the parameters. With ``gain="auto"`` (or ``"auto:HZ"``) ``fit`` calibrates the
    gain on the training recordings, labels unused, as ``neurotex train --gain auto``
    does, and ``transform`` encodes every later recording with that gain: ``gain_`` holds
    it and ``gain_calibration_`` how it was chosen (``None`` for a number).

    Parameters are those of :func:`neurotex.features`: ``method``, ``encoding``, ``gain``,
    ``preset``, ``overshoot``, ``cutoff``, ``baseline``, ``whole``, ``levels``, ``bin_ms``,
    ``distances``, ``symmetric``, ``fa_gain``, ``haralick``, ``bin_widths``,
    ``window_mm``, ``spectrum_bins``, ``spectrum_bands``, ``travel_mm``, and ``fs`` for bare
    arrays."""

    def __init__(
        self,
        method: str = "glcm3d",
        encoding: str = _DEFAULTS["encoding"],
        gain: Union[float, str] = _DEFAULTS["gain"],
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
        fs: float = 1000.0,
    ) -> None:
        self.method = method
        self.encoding = encoding
        self.gain = gain
        self.preset = preset
        self.overshoot = overshoot
        self.cutoff = cutoff
        self.baseline = baseline
        self.whole = whole
        self.levels = levels
        self.bin_ms = bin_ms
        self.distances = distances
        self.symmetric = symmetric
        self.fa_gain = fa_gain
        self.haralick = haralick
        self.bin_widths = bin_widths
        self.window_mm = window_mm
        self.spectrum_bins = spectrum_bins
        self.spectrum_bands = spectrum_bands
        self.travel_mm = travel_mm
        self.fs = fs

    def _kwargs(self) -> Dict[str, Any]:
        p = self.get_params()
        p.pop("method")
        p.pop("encoding")
        return p

    def fit(self, X: Any, y: Any = None) -> "SpikeFeatures":
        """Checks the parameters (raising :class:`neurotex.ParameterError`) and, under
        ``gain="auto"``, calibrates the gain on ``X``; learns nothing else."""
        from . import _calibrate, _stage_options

        opts = _stage_options(
            gain=self.gain, preset=self.preset, overshoot=self.overshoot, cutoff=self.cutoff,
            baseline=self.baseline, whole=self.whole, levels=self.levels, bin_ms=self.bin_ms,
            distances=tuple(self.distances), symmetric=self.symmetric,
            encoding=self.encoding, fa_gain=self.fa_gain, haralick=self.haralick,
            bin_widths=tuple(self.bin_widths), window_mm=self.window_mm,
            spectrum_bins=self.spectrum_bins, spectrum_bands=self.spectrum_bands,
            travel_mm=self.travel_mm,
        )
        _native.check_options(self.method, opts)
        if isinstance(self.gain, str):
            calibration, _ = _calibrate(X, opts, self.fs, None)
            self.gain_calibration_ = calibration
            # a number written as text ("8") calibrates nothing
            self.gain_ = float(self.gain) if calibration is None else calibration.gain
        else:
            self.gain_calibration_ = None
            self.gain_ = self.gain
        self.n_recordings_seen_ = len(X)
        self.feature_names_out_: Optional[List[str]] = None
        return self

    def transform(self, X: Any) -> np.ndarray:
        """The feature matrix ``(n, k)``, float64."""
        check_is_fitted(self, "n_recordings_seen_")
        kwargs = self._kwargs()
        kwargs["gain"] = self.gain_
        values, names = _features(X, self.method, self.encoding, **kwargs)
        self.feature_names_out_ = names
        return values

    def get_feature_names_out(self, input_features: Any = None) -> np.ndarray:
        """The column names of the last :meth:`transform` (they depend on the grid)."""
        check_is_fitted(self, "n_recordings_seen_")
        if self.feature_names_out_ is None:
            raise ValueError("the feature names are known after the first transform")
        return np.asarray(self.feature_names_out_, dtype=object)

    def __sklearn_tags__(self):  # noqa: D105
        tags = super().__sklearn_tags__()
        tags.input_tags.two_d_array = False
        tags.input_tags.three_d_array = True
        tags.requires_fit = True
        return tags


class _LibraryClassifier(ClassifierMixin, BaseEstimator):
    """A classifier of the library fitted on a feature matrix."""

    _kind = ""

    def _options(self) -> Dict[str, Any]:
        return {k: v for k, v in self.get_params().items() if v is not None}

    def fit(self, X: Any, y: Any) -> "_LibraryClassifier":
        """Fits on ``X`` (n_samples, n_features) and labels ``y``."""
        X, y = validate_data(self, X, y, dtype=np.float64, y_numeric=False)
        from sklearn.utils.multiclass import check_classification_targets

        check_classification_targets(y)
        self.classes_ = np.unique(y)
        # Classes are indexed in order of first appearance, as the CLI indexes them, so
        # that ties resolve as they do there.
        first = {}
        for label in y:
            first.setdefault(label, len(first))
        self._order = np.array(list(first), dtype=self.classes_.dtype)
        index = np.array([first[label] for label in y], dtype=np.int64)
        self._training = (np.ascontiguousarray(X), [int(i) for i in index])
        self._fitted = self._fit_native()
        # columns of the library's shares -> columns in classes_ order
        self._to_sorted = np.searchsorted(self.classes_, self._order)
        return self

    def _fit_native(self) -> Any:
        X, index = self._training
        return _native.FittedClassifier.fit(self._kind, self._options(), X, index)

    def __getstate__(self) -> Dict[str, Any]:
        # The native model is not picklable; the training set is kept instead and the
        # (deterministic, seeded) fit repeated on unpickling, giving the same model.
        state = self.__dict__.copy()
        state.pop("_fitted", None)
        return state

    def __setstate__(self, state: Dict[str, Any]) -> None:
        self.__dict__.update(state)
        if "_training" in state:
            self._fitted = self._fit_native()

    def predict(self, X: Any) -> np.ndarray:
        """The predicted label of each row."""
        check_is_fitted(self, "_fitted")
        X = validate_data(self, X, dtype=np.float64, reset=False)
        predicted, _ = self._fitted.predict(np.ascontiguousarray(X))
        return self._order[np.asarray(predicted, dtype=np.int64)]

    def predict_proba(self, X: Any) -> np.ndarray:
        """Each class's share, columns in ``classes_`` order."""
        check_is_fitted(self, "_fitted")
        X = validate_data(self, X, dtype=np.float64, reset=False)
        _, shares = self._fitted.predict(np.ascontiguousarray(X))
        out = np.zeros((shares.shape[0], len(self.classes_)))
        n = min(shares.shape[1], len(self._order))
        out[:, self._to_sorted[:n]] = shares[:, :n]
        return out


class KNNClassifier(_LibraryClassifier):
    """k nearest neighbours (Euclidean, majority vote; a tie goes to the tied class with
    the nearest member), features z-scored with training statistics unless
    ``standardize=False``: the paper's classifier, as ``neurotex evaluate`` runs it."""

    _kind = "knn"

    def __init__(self, k: int = _KNN["k"], standardize: bool = _KNN["standardize"]) -> None:
        self.k = k
        self.standardize = standardize


class RandomForestClassifier(_LibraryClassifier):
    """The library's random forest (``--classifier forest``): ``trees`` CART trees, each
    grown on a bootstrap sample (``bootstrap=False``: the whole training set) to
    ``max_depth`` (``None``: until leaves are pure or smaller than ``min_samples_leaf``),
    trying ``max_features`` features at each split (``None``: ⌊√d⌋, scikit-learn's
    ``"sqrt"``, not its ``None``, which tries all), seeded by ``seed`` (scikit-learn's
    ``random_state``). The names are the CLI's (``--trees`` is scikit-learn's
    ``n_estimators``); the defaults are the library's, as ``neurotex train`` uses them."""

    _kind = "forest"

    def __init__(
        self,
        trees: int = _FOREST["trees"],
        max_depth: Optional[int] = _FOREST["max_depth"],
        min_samples_leaf: int = _FOREST["min_samples_leaf"],
        max_features: Optional[int] = _FOREST["max_features"],
        bootstrap: bool = _FOREST["bootstrap"],
        seed: int = _FOREST["seed"],
    ) -> None:
        self.trees = trees
        self.max_depth = max_depth
        self.min_samples_leaf = min_samples_leaf
        self.max_features = max_features
        self.bootstrap = bootstrap
        self.seed = seed


class LogisticRegression(_LibraryClassifier):
    """The library's multinomial logistic regression (``--classifier linear``), L2
    penalty of inverse strength ``c`` (scikit-learn's ``C``, spelled as the CLI's
    ``--c``), fitted by L-BFGS for at most ``max_iter`` iterations until no gradient
    component exceeds ``tol``; features are z-scored with training statistics."""

    _kind = "linear"

    def __init__(
        self,
        c: float = _LINEAR["c"],
        max_iter: int = _LINEAR["max_iter"],
        tol: float = _LINEAR["tol"],
    ) -> None:
        self.c = c
        self.max_iter = max_iter
        self.tol = tol

    def fit(self, X: Any, y: Any) -> "LogisticRegression":
        """Fits on ``X`` and ``y``; ``n_iter_`` holds the L-BFGS iterations."""
        super().fit(X, y)
        self.n_iter_ = np.array([self._fitted.n_iter])
        return self


class SpikingClassifier(ClassifierMixin, BaseEstimator):
    """A spiking network trained on the recordings' spike trains (``neurotex train
    --classifier snn``; docs/spiking-classifier.md): recordings in, labels out, no
    features. ``X`` is what :class:`SpikeFeatures` takes (arrays ``(T, rows, cols)``, a
    4-D array, or :class:`neurotex.Recording` objects); ``fit`` encodes them with the
    pipeline (``encoding``, ``gain``, ``baseline``, ``causal``; the paper's defaults
    otherwise: a list of recordings does not carry its dataset's baseline, so give
    ``baseline=dataset.baseline``) and trains
    ``hidden`` LIF neurons with time steps of ``dt_ms`` for at most ``epochs`` passes, early
    stopping on 20 % of each class of ``X``, seeded by ``seed``; ``recurrent`` and
    ``reset`` (``"zero"`` or ``"subtract"``), ``target`` (``"float"`` or ``"xylo"``) and
    ``window_ms`` (train on windows of that many ms), ``train_decays`` (each hidden
    neuron's decays trained), ``travel`` (time in steps of travel), ``warp`` (train on
    time-warped recordings), ``adapt_ms`` with ``adapt_strength`` (adaptive thresholds)
    and ``delay_ms`` (learnable synaptic delays) as :meth:`neurotex.SpikingModel.train`. ``model_`` is the trained
    :class:`neurotex.SpikingModel` (save it for ``neurotex predict``, stream it, export
    it to NIR)."""

    def __init__(
        self,
        hidden: int = _SNN_DEFAULTS["hidden"],
        dt_ms: int = _SNN_DEFAULTS["dt_ms"],
        epochs: int = _SNN_DEFAULTS["epochs"],
        readout: str = _SNN_DEFAULTS["readout"],
        seed: int = _SNN_DEFAULTS["seed"],
        recurrent: bool = _SNN_DEFAULTS["recurrent"],
        reset: Optional[str] = None,
        target: str = _SNN_DEFAULTS["target"],
        window_ms: Optional[int] = _SNN_DEFAULTS["window_ms"],
        train_decays: bool = _SNN_DEFAULTS["train_decays"],
        travel: Union[str, float] = _SNN_DEFAULTS["travel"],
        warp: Optional[float] = _SNN_DEFAULTS["warp"],
        adapt_ms: Optional[float] = _SNN_DEFAULTS["adapt_ms"],
        adapt_strength: float = _SNN_DEFAULTS["adapt_strength"],
        delay_ms: Optional[float] = _SNN_DEFAULTS["delay_ms"],
        encoding: str = _DEFAULTS["encoding"],
        gain: Union[float, str] = _DEFAULTS["gain"],
        baseline: Optional[str] = None,
        causal: bool = False,
        fs: float = 1000.0,
    ) -> None:
        self.hidden = hidden
        self.dt_ms = dt_ms
        self.epochs = epochs
        self.readout = readout
        self.seed = seed
        self.recurrent = recurrent
        self.reset = reset
        self.target = target
        self.window_ms = window_ms
        self.train_decays = train_decays
        self.travel = travel
        self.warp = warp
        self.adapt_ms = adapt_ms
        self.adapt_strength = adapt_strength
        self.delay_ms = delay_ms
        self.encoding = encoding
        self.gain = gain
        self.baseline = baseline
        self.causal = causal
        self.fs = fs

    def fit(self, X: Any, y: Any) -> "SpikingClassifier":
        """Trains on recordings ``X`` and labels ``y``."""
        from sklearn.utils.multiclass import check_classification_targets

        from . import SpikingModel

        y = np.asarray(y)
        check_classification_targets(y)
        if len(y) != len(X):
            raise ValueError(f"{len(y)} labels for {len(X)} recordings")
        self.classes_ = np.unique(y)
        self.model_ = SpikingModel.train(
            X, [str(label) for label in y], fs=self.fs, hidden=self.hidden,
            dt_ms=self.dt_ms, epochs=self.epochs, readout=self.readout, seed=self.seed,
            recurrent=self.recurrent, reset=self.reset, target=self.target,
            window_ms=self.window_ms, train_decays=self.train_decays, travel=self.travel,
            warp=self.warp, adapt_ms=self.adapt_ms, adapt_strength=self.adapt_strength,
            delay_ms=self.delay_ms, causal=self.causal,
            encoding=self.encoding, gain=self.gain,
            baseline=self.baseline,
        )
        # the network's outputs (labels as text) -> columns in classes_ order
        text = [str(c) for c in self.classes_]
        self._columns = np.array([self.model_.classes_.index(t) for t in text])
        return self

    def predict(self, X: Any) -> np.ndarray:
        """The predicted label of each recording (the network's: a tie goes to the class
        of its first output)."""
        check_is_fitted(self, "model_")
        of_text = {str(c): c for c in self.classes_}
        return np.array([of_text[t] for t in self.model_.predict(X, fs=self.fs)],
                        dtype=self.classes_.dtype)

    def predict_proba(self, X: Any) -> np.ndarray:
        """Each class's share (the softmax of the network's scores), columns in
        ``classes_`` order."""
        check_is_fitted(self, "model_")
        return self.model_.predict_proba(X, fs=self.fs)[:, self._columns]

    def __getstate__(self) -> Dict[str, Any]:
        # The native model is not picklable; its model file is kept instead.
        import os
        import tempfile

        state = self.__dict__.copy()
        model = state.pop("model_", None)
        if model is not None:
            with tempfile.TemporaryDirectory() as tmp:
                path = os.path.join(tmp, "model.json")
                model.save(path)
                with open(path, "rb") as f:
                    state["_model_file"] = f.read()
        return state

    def __setstate__(self, state: Dict[str, Any]) -> None:
        import os
        import tempfile

        from . import SpikingModel

        data = state.pop("_model_file", None)
        self.__dict__.update(state)
        if data is not None:
            with tempfile.TemporaryDirectory() as tmp:
                path = os.path.join(tmp, "model.json")
                with open(path, "wb") as f:
                    f.write(data)
                self.model_ = SpikingModel.load(path)

    def __sklearn_tags__(self):  # noqa: D105
        tags = super().__sklearn_tags__()
        tags.input_tags.two_d_array = False
        tags.input_tags.three_d_array = True
        return tags
