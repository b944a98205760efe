"""3D-GLCM features of a dataset folder on a Dask cluster, one task per shard of
recordings; the result equals ``neurotex.features(folder)`` bit for bit.

    python examples/dask_features.py DATASET_DIR [--workers 2] [--shard 40]

Each task reads its own shard of the folder (``load_dataset(dir, rows=...)``), so no
samples travel through the scheduler, only the small feature rows come back. On a real
cluster, replace ``LocalCluster`` with your scheduler's address (``Client("tcp://...")``)
and put the folder where every worker can read it.
"""

from __future__ import annotations

import argparse
import csv
import os

import numpy as np

import neurotex


def manifest_rows(folder: str) -> int:
    """The number of recordings the folder's manifest lists."""
    with open(os.path.join(folder, "manifest.csv"), newline="") as f:
        return sum(1 for _ in csv.DictReader(f))


def shard_features(folder: str, rows: list, method: str, options: dict):
    """One task: the features of manifest rows ``rows``."""
    shard = neurotex.load_dataset(folder, rows=rows)
    return neurotex.features(shard, method, **options)


def dask_features(client, folder: str, method: str = "glcm3d", shard: int = 40, **options):
    """``(X, names)`` of every recording in ``folder``, computed by ``client``'s workers."""
    n = manifest_rows(folder)
    shards = [list(range(i, min(i + shard, n))) for i in range(0, n, shard)]
    futures = client.map(shard_features, [folder] * len(shards), shards,
                         [method] * len(shards), [options] * len(shards), pure=False)
    parts = client.gather(futures)
    names = parts[0][1]
    return np.vstack([x for x, _ in parts]), names


def main() -> None:
    from dask.distributed import Client, LocalCluster

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder")
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--shard", type=int, default=40)
    ap.add_argument("--method", default="glcm3d")
    args = ap.parse_args()
    # One thread per worker: neurotex parallelises inside a task with its own threads.
    with LocalCluster(n_workers=args.workers, threads_per_worker=1,
                      processes=True, dashboard_address=None) as cluster, Client(cluster) as client:
        X, names = dask_features(client, args.folder, args.method, args.shard)
    print(f"{X.shape[0]} recordings x {X.shape[1]} features ({', '.join(names)})")
    local, _ = neurotex.features(args.folder, args.method)
    print("equal to neurotex.features(folder):", bool(np.array_equal(X, local)))


if __name__ == "__main__":
    main()
