"""A neurotex dataset folder served the way tonic serves neuromorphic datasets, so that
tonic's transforms and a PyTorch ``DataLoader`` take neurotex's spikes as they take any
event dataset::

    import tonic
    from neurotex.tonic import Dataset

    data = Dataset("fabricslide/", encoding="sa+fa",
                   transform=tonic.transforms.ToFrame(sensor_size=..., time_window=10_000))
    frames, target = data[0]

Items are ``(events, target)``: the recording's spikes as tonic's structured array
(:data:`neurotex.EVENT_DTYPE`, ``t`` in microseconds, ``p`` 1 for ON and 0 for OFF) and the
index of its label in :attr:`Dataset.classes`. An address-event dataset's events are read
as every neurotex command reads them; a sampled dataset's recordings are encoded with the
stage options, one recording per item, as tonic reads one file per item. Nothing here
imports tonic or torch.
"""

from __future__ import annotations

import os
from typing import Any, Callable, List, Optional, Tuple, Union

import numpy as np

from . import EVENT_DTYPE, _event_arrays, _native, _stage_options

__all__ = ["Dataset"]


class Dataset:
    """A dataset folder with tonic's dataset interface: ``len(data)``, ``data[i]`` giving
    ``(events, target)`` with ``transform``, ``target_transform`` and ``transforms``
    applied as tonic applies them, and tonic's attributes ``sensor_size`` (``(cols, rows,
    2)``: x, y and the two polarities), ``ordering`` (``"xytp"``), ``dtype``, ``classes``
    (the labels, sorted) and ``targets`` (each recording's class index).

    ``encoding`` chooses the populations: ``"sa+fa"`` (the default) both polarities,
    ``"sa"`` ON events only (what a dataset without polarities has), ``"fa"`` OFF only.
    Events are neurotex's spikes: 1 ms steps, at most one per cell, polarity and
    millisecond, ``p`` renumbered 1/0. Further keywords are the stage options of
    :func:`neurotex.features` (``gain``, ``preset``, ``cutoff``, ...), used to encode a
    sampled dataset; ``gain="auto"`` and ``causal=True`` are refused (they calibrate on a
    whole dataset: pass the gain instead).

    Raises :class:`neurotex.NotFoundError` for a missing folder, :class:`neurotex.DataError`
    for a bad recording (when its item is read) and :class:`neurotex.ParameterError` for a
    broken option."""

    ordering = "xytp"
    dtype = EVENT_DTYPE

    def __init__(self, path: Union[str, os.PathLike], encoding: str = "sa+fa", *,
                 transform: Optional[Callable[[np.ndarray], Any]] = None,
                 target_transform: Optional[Callable[[int], Any]] = None,
                 transforms: Optional[Callable[[np.ndarray, int], Tuple[Any, Any]]] = None,
                 **stage_options: Any) -> None:
        self.path = os.fspath(path)
        self.transform = transform
        self.target_transform = target_transform
        self.transforms = transforms
        self._options = _stage_options(encoding=encoding, **stage_options)
        _, rows, grid = _native.dataset_events(self.path, self._options, [0])
        self.rows: List[dict] = list(rows)
        self.classes: List[str] = sorted({r["label"] for r in self.rows})
        self.targets: List[int] = [self.classes.index(r["label"]) for r in self.rows]
        n_rows, n_cols = grid if grid is not None else (0, 0)
        self.sensor_size: Tuple[int, int, int] = (n_cols, n_rows, 2)

    def __len__(self) -> int:
        return len(self.rows)

    def __getitem__(self, index: int) -> Tuple[Any, Any]:
        if not -len(self) <= index < len(self):
            raise IndexError(f"index {index} is outside the dataset's {len(self)} recordings")
        index %= len(self)
        columns, _, _ = _native.dataset_events(self.path, self._options, [index])
        events: Any = _event_arrays(columns)[0]
        target: Any = self.targets[index]
        if self.transform is not None:
            events = self.transform(events)
        if self.target_transform is not None:
            target = self.target_transform(target)
        if self.transforms is not None:
            events, target = self.transforms(events, target)
        return events, target

    def __repr__(self) -> str:
        return (f"neurotex.tonic.Dataset({self.path!r}: {len(self)} recordings, "
                f"{len(self.classes)} classes, sensor_size={self.sensor_size})")
