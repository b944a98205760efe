"""Public tactile datasets by recipe, as ``neurotex datasets`` and ``neurotex benchmark``
serve them (docs/benchmark.md): the same recipes, cache and leaderboard as the command
line::

    import neurotex
    from neurotex import datasets

    datasets.fetch("fabricslide", source="shared/data/fabricslide/fabric")
    data = datasets.load("fabricslide")                  # a neurotex.Dataset
    events = datasets.tonic("fabricslide", encoding="sa+fa")   # tonic's dataset interface
    board = neurotex.benchmark(["fabricslide"], "bench/")      # the leaderboard, as a dict

``cache`` is the cache folder everywhere (default: ``$NEUROTEX_CACHE``, else
``$XDG_CACHE_HOME/neurotex``, else ``~/.cache/neurotex``); ``source`` is a local copy of a
dataset's sources (the command line's ``--from``); without one, the sources are downloaded
(an interrupted download resumes on the next call).
"""

from __future__ import annotations

import os
from typing import Any, Dict, List, Optional, Sequence, Union

from . import _native, load_dataset

__all__ = ["list_recipes", "check", "fetch", "path", "load", "tonic", "benchmark"]

PathLike = Union[str, "os.PathLike[str]"]


def _opt(p: Optional[PathLike]) -> Optional[str]:
    return None if p is None else os.path.abspath(os.fspath(p))


def list_recipes(cache: Optional[PathLike] = None) -> List[Dict[str, Any]]:
    """The built-in recipes: each ``{"recipe": {...}, "fetched": folder or None}``."""
    return _native.datasets_list(_opt(cache))


def check(recipe: Union[str, PathLike]) -> Dict[str, Any]:
    """The recipe (a built-in name or a recipe file), checked, as a dict. Raises
    :class:`neurotex.DataError` naming the key of a rule it breaks."""
    return _native.datasets_check(os.fspath(recipe))


def fetch(name: Union[str, PathLike], source: Optional[PathLike] = None,
          cache: Optional[PathLike] = None) -> str:
    """Fetches a dataset into the cache, downloaded or from the local copy ``source`` (every
    checksum verified, imported once; reused when fetched before), and returns its dataset
    folder."""
    return _native.datasets_fetch(os.fspath(name), _opt(source), _opt(cache))


def path(name: Union[str, PathLike], cache: Optional[PathLike] = None) -> str:
    """The dataset folder of a fetched dataset; :class:`neurotex.DataError` when it is not
    in the cache."""
    return _native.datasets_path(os.fspath(name), _opt(cache))


def load(name: Union[str, PathLike], source: Optional[PathLike] = None,
         cache: Optional[PathLike] = None, rows: Optional[Sequence[int]] = None) -> Any:
    """The dataset as :func:`neurotex.load_dataset` reads it, fetched first when needed."""
    return load_dataset(fetch(name, source, cache), rows)


def tonic(name: Union[str, PathLike], encoding: str = "sa+fa", *,
          source: Optional[PathLike] = None, cache: Optional[PathLike] = None,
          **kwargs: Any) -> Any:
    """The dataset with tonic's dataset interface (:class:`neurotex.tonic.Dataset`:
    ``(events, target)`` items, ``transform``...), fetched first when needed."""
    from .tonic import Dataset

    return Dataset(fetch(name, source, cache), encoding, **kwargs)


def _share(task: Sequence[Any]) -> None:
    """One share of :func:`benchmark` (a dataset x protocol x encoding x feature method), as
    a Dask task: its candidates' finished pieces kept in ``out`` for the leaderboard's run
    to take."""
    share, out, cache, snn, folds, repeats, seed = task
    _native.benchmark_share(tuple(share), out, cache, snn, folds, repeats, seed)


def benchmark(datasets: Sequence[Union[str, PathLike]], out: PathLike, *,
              cache: Optional[PathLike] = None, source: Optional[PathLike] = None,
              protocols: Optional[Sequence[str]] = None, snn: bool = False, folds: int = 5,
              repeats: int = 1, seed: int = 0, client: Any = None) -> Dict[str, Any]:
    """``neurotex benchmark``: under each protocol of each dataset's recipe, the fixed
    candidate set compared with nested selection, written into ``out`` (leaderboard.md,
    leaderboard.json, each comparison's folder); returns the leaderboard as a dict.

    With a Dask ``client``, each dataset x protocol x encoding x feature method of the
    candidate set (the method's candidates under every classifier; the baselines without
    spikes together) is one task on the cluster, and each task encodes the dataset for
    itself; the workers must see ``out`` and ``cache`` (a shared file system,
    or a local cluster). Every dataset is fetched here first, the tasks keep their
    candidates' finished pieces in ``out``, and the leaderboard's run then takes them: the
    same leaderboard as without a client."""
    # A recipe file by its absolute path, so that a worker elsewhere finds it too.
    names = [os.path.abspath(os.fspath(d)) if os.fspath(d).endswith(".toml")
             or os.sep in os.fspath(d) else os.fspath(d) for d in datasets]
    out_s, cache_s = _opt(out), _opt(cache)
    wanted = list(protocols or [])
    if client is not None:
        if source is not None and len(names) > 1:
            raise ValueError("source is the copy of one dataset's sources: one dataset with it")
        shares = _native.benchmark_shares(names, out_s, cache_s, _opt(source), wanted, snn,
                                          folds, repeats, seed)
        tasks = [(share, out_s, cache_s, snn, folds, repeats, seed) for share in shares]
        client.gather(client.map(_share, tasks, pure=False))
    return _native.benchmark(names, out_s, cache_s, _opt(source), wanted, snn, folds,
                             repeats, seed)
