r"""The snnTorch peer of the criterion bench `snn/train_epoch/55x32x1200`
(crates/neurotex-bench/benches/snn.rs): one training epoch of the same spiking classifier
on data of the same shapes and rates, written the way an snnTorch user would write it; with
`--inputs DIR`, the same epoch on real recordings' input spikes (`neurotex export inputs`).

Needs torch and snntorch, in a throwaway virtual environment outside the repository; it is
never run in CI and nothing imports it:

    python3 -m venv /tmp/snnpeer
    /tmp/snnpeer/bin/pip install torch --index-url https://download.pytorch.org/whl/cpu
    /tmp/snnpeer/bin/pip install snntorch "numpy<2"   # numpy<2 only for a torch built on 1.x
    /tmp/snnpeer/bin/python crates/neurotex-bench/benches/peers/snntorch_snn.py \
        [--dtype float64|float32|both] [--reset manual|delay|nodelay] [--hoist] [--epochs 7]
        [--threads 2] [--inputs DIR] [--standardize on|off]

Where the PyTorch index cannot be reached (PyPI's Linux x86-64 torch is the CUDA build,
which does not import without its nvidia-* libraries), Debian bookworm's CPU-only
python3-torch 1.13.1 serves, unpacked rather than installed:

    mkdir -p /tmp/debtorch/debs && cd /tmp/debtorch/debs && apt-get download $(apt-get -s \
        install --no-install-recommends python3-torch libopenblas0-pthread | awk '/^Inst/ \
        {print $2}' | grep -v '^python3-\(numpy\|sympy\|mpmath\)$')
    for f in *.deb; do dpkg-deb -x "$f" /tmp/debtorch/root; done
    R=/tmp/debtorch/root; /tmp/snnpeer/bin/pip install "numpy<2" sympy typing_extensions
    L=$R/usr/lib/x86_64-linux-gnu; L=$L:$L/openblas-pthread:$R/usr/lib:$R/lib/x86_64-linux-gnu
    cd /work/main && PYTHONPATH=$R/usr/lib/python3/dist-packages LD_LIBRARY_PATH=$L \
        /tmp/snnpeer/bin/python crates/neurotex-bench/benches/peers/snntorch_snn.py

and, back to back on the same host (these machines are noisy),
`cargo bench -p neurotex-bench --bench snn -- train_epoch`, whose median is
`median.point_estimate` (ns) in target/criterion/snn_train_epoch_55x32x1200/new/estimates.json.
It also runs with a current torch (2.x, CPU, numpy 2.x) and snntorch 1.0.0 from PyPI.
Run nothing else meanwhile: torch's threads spin, and beside a compiler an epoch took 30
times longer.

The work, as the Rust bench's `fit` with one epoch does it (neurotex-learn src/snn):
55 recordings of 32 inputs x 1200 steps of 10 ms, class `i % 5`, an input spiking with
probability 0.08 per step when `input * 5 // 32` is its recording's class and 0.02
otherwise (numpy, seeded; the Rust bench draws its own with xorshift: same rates, not the
same spikes). A stratified validation split of round(0.2 * 11) = 2 recordings per class:
45 trained in shuffled batches of 8 (5 of 8 and one of 5) and 10 held out. The network:

    input (32) -> Linear -> snn.Synaptic, 128 hidden (alpha = exp(-10/20), beta =
    exp(-10/40), threshold 1, reset to zero, fast-sigmoid surrogate of slope 10)
    -> Linear -> snn.Leaky(beta = exp(-10/40), reset_mechanism="none"), whose membrane is
    the readout O[t] = k O[t-1] + W_out S[t] + b_out; class scores = mean of O over time

with neurotex's initial weights (input weights normal with the fluctuation-driven spread
from the training data's mean rate, readout weights uniform in +-1/sqrt(128), biases 0),
softmax cross-entropy (mean over the batch), BPTT over all 1200 steps, Adam lr 0.005, then
a no-grad forward over the 10 validation recordings for the validation loss. Each timed
epoch starts from a fresh network and optimizer, as each iteration of the Rust bench does.
torch.set_num_threads(2), as neurotex uses 2 rayon threads on these 2-core machines.
snnTorch's fast_sigmoid returns float32 spikes whatever its input, so in float64 the spikes
are cast back to float64 (one more graph node per step).

The reset (`--reset`):
  manual   (default) snn.Synaptic with reset_mechanism="none" and the reset to zero applied
           by hand with the spike detached, V[t] = P[t] (1 - S[t].detach()): neurotex's
           dynamics and gradient exactly (a spike at P >= 1 in neurotex, P > 1 in snnTorch).
  delay    snn.Synaptic(reset_mechanism="zero", reset_delay=True), snnTorch's default: the
           reset is detached (`mem_reset` detaches it) but applied one step late, to the
           next step's whole membrane, so a neuron that spiked sits at 0 for a step.
  nodelay  snn.Synaptic(reset_mechanism="zero", reset_delay=False): neurotex's timing, but
           the reset is not detached (the gradient flows through the spike in V = P(1-S)).
`--hoist` applies the input Linear to all 1200 steps in one call before the time loop
instead of step by step as the snnTorch tutorials do (same result, fewer graph nodes), and
splits it with `unbind` (indexing it step by step makes the backward pass quadratic).

Real inputs (`--inputs DIR`): DIR is what `neurotex export inputs` writes, one `(steps,
inputs)` NPY of spike counts per 10 ms step per recording and index.csv (`file,label,
array`). Make it with a trained model of the pipeline, e.g. for FabricSlide at 50 mm/s
(69 slides of about 12 s, 5 textures, sa+fa = 32 inputs, gain 8):

    neurotex train --dataset DS --classifier snn --encoding sa+fa --speeds 50 --out snn.json
    neurotex export inputs --model snn.json --dataset DS --speeds 50 --out inputs

The network's shapes come from the data (inputs, 128 hidden, one class per label, labels
sorted); decays, surrogate, reset, readout, initialisation (the rate from the training
recordings' counts), Adam, batches of 8 and the validation split rule are those above.
Recordings of different lengths are zero-padded to the longest of each batch; each
recording's score is the mean of its readout over its own steps (the padded steps are
computed, which neurotex does not do, and masked out of the mean). Inputs are standardised
as neurotex's default does (`--standardize on`, the default with --inputs): each input's
mean count per step in each training recording, their mean mu and spread sd (population,
at least 0.001) over the training recordings; the network trains on z = (x - mu) / sd,
computed once before the epochs, with the input Linear's weights V = W sd and bias
c = sum_i mu_i W_i at the start (the same initial current as W x), so Adam moves V and c as
neurotex's moves its standardised parameters. neurotex folds them back into the network's
W and b after every batch and runs on the counts; here the Linear stays on z, the same
network. The synthetic mode defaults to `--standardize off`, as it was first measured; the
Rust bench now standardises (`SnnParams::default()`), which `--standardize on` matches.
Also printed: the share of input x step cells (padding excluded) with at least one spike
and the mean spike count per input per step.

neurotex's time per epoch on the same recordings: whole `neurotex train ... --snn-epochs
2` and `--snn-epochs 12` processes (early stopping cannot end a run before epoch 16),
timed back to back with this script, the difference over the 10 extra epochs (reading and
encoding cancel); `RAYON_NUM_THREADS=1` for one thread.

Differences that stay: snnTorch runs a batch as one (batch x hidden) tensor per step and
autograd records the graph, where neurotex runs each recording's forward and hand-written
backward pass separately (the batch's recordings split over 2 threads) and touches only
the inputs and hidden neurons that spiked; the dense tensors cost the same whatever spikes.

Prints one JSON line per dtype: median and samples of the epoch time (ms; the median also
in s), the data's shapes and input density, the split, versions, setup.
"""

import argparse
import csv
import json
import os
import math
import statistics
import time

import numpy as np
import snntorch
import snntorch as snn
import torch
from snntorch import surrogate
from torch import nn

INPUTS, STEPS, CLASSES, RECORDINGS, HIDDEN = 32, 1200, 5, 55, 128  # the synthetic data's
DT_MS, TAU_SYN_MS, TAU_MEM_MS, TAU_OUT_MS = 10.0, 20.0, 40.0, 40.0
BATCH, LEARNING_RATE, VALIDATION, SLOPE = 8, 0.005, 0.2, 10.0
ALPHA, BETA, KAPPA = (math.exp(-DT_MS / t) for t in (TAU_SYN_MS, TAU_MEM_MS, TAU_OUT_MS))


def recordings(rng):
    """(RECORDINGS, STEPS, INPUTS) of 0/1 spikes and the class of each."""
    y = np.arange(RECORDINGS) % CLASSES
    own = (np.arange(INPUTS) * CLASSES // INPUTS)[None, :] == y[:, None]
    rate = np.where(own, 0.08, 0.02)[:, None, :]
    x = (rng.random((RECORDINGS, STEPS, INPUTS)) < rate).astype(np.float64)
    return x, y


def exported(folder):
    """`neurotex export inputs`' folder: (steps_max, recordings, inputs) of spike counts per
    step, zero after each recording's end; each recording's steps, class index (labels
    sorted) and the labels."""
    with open(os.path.join(folder, "index.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        raise SystemExit(f"{folder}/index.csv lists no recording")
    arrays = [np.load(os.path.join(folder, r["array"])).astype(np.float64) for r in rows]
    labels = sorted({r["label"] for r in rows})
    y = np.array([labels.index(r["label"]) for r in rows])
    lengths = np.array([a.shape[0] for a in arrays])
    x = np.zeros((lengths.max(), len(arrays), arrays[0].shape[1]))
    for i, a in enumerate(arrays):
        x[:a.shape[0], i] = a
    return x, y, lengths, labels


def validation_split(y, rng, classes=CLASSES):
    """Each class's recordings shuffled, round(share * n) (at least 1) held out."""
    train, valid = [], []
    for c in range(classes):
        members = rng.permutation(np.flatnonzero(y == c))
        held = min(max(int(round(len(members) * VALIDATION)), 1), len(members) - 1)
        valid += members[:held].tolist()
        train += members[held:].tolist()
    return sorted(train), sorted(valid)


def kernel_energy(alpha, beta):
    """Sum over t of the squared membrane response to one unit input (as neurotex)."""
    current, membrane, energy = 1.0, 0.0, 0.0
    for _ in range(100_000):
        membrane = beta * membrane + current
        current *= alpha
        energy += membrane * membrane
        if membrane < 1e-9 * math.sqrt(energy):
            break
    return energy


def standardisation(x, lengths, train):
    """neurotex's standardised inputs: each input's mean count per step in each training
    recording; their mean and spread (population, at least 0.001) across the recordings."""
    rates = np.stack([x[:lengths[r], r].mean(axis=0) for r in train])
    return rates.mean(axis=0), np.maximum(rates.std(axis=0), 1e-3)


class Net(nn.Module):
    def __init__(self, reset, hoist, sigma, gen, inputs=INPUTS, classes=CLASSES, scale=None):
        """`scale`: (mean, spread) of standardised inputs. The network then trains on
        z = (x - mean) / spread with the Linear's weights V = W spread and bias
        c = sum_i mean_i W_i, the same initial current as W x (neurotex's moved
        parameters, which it folds back to W = V / spread after each step)."""
        super().__init__()
        self.reset, self.hoist, self.classes = reset, hoist, classes
        grad = surrogate.fast_sigmoid(slope=SLOPE)
        self.fc1 = nn.Linear(inputs, HIDDEN)
        if reset == "manual":
            self.lif = snn.Synaptic(alpha=ALPHA, beta=BETA, threshold=1.0, spike_grad=grad,
                                    reset_mechanism="none")
        else:
            self.lif = snn.Synaptic(alpha=ALPHA, beta=BETA, threshold=1.0, spike_grad=grad,
                                    reset_mechanism="zero", reset_delay=(reset == "delay"))
        self.fc2 = nn.Linear(HIDDEN, classes)
        self.out = snn.Leaky(beta=KAPPA, reset_mechanism="none")
        bound = 1.0 / math.sqrt(HIDDEN)
        with torch.no_grad():
            self.fc1.weight.normal_(0.0, sigma, generator=gen)
            self.fc1.bias.zero_()
            self.fc2.weight.uniform_(-bound, bound, generator=gen)
            self.fc2.bias.zero_()
            if scale is not None:
                mean, spread = (torch.as_tensor(v, dtype=self.fc1.weight.dtype)
                                for v in scale)
                self.fc1.bias.copy_(self.fc1.weight @ mean)
                self.fc1.weight.mul_(spread)

    def forward(self, x, lengths=None):
        """x: (steps, batch, inputs) -> class scores (batch, classes). With `lengths`
        (recordings of different lengths, zero-padded to the longest), each recording's
        score is the mean over its own steps (the padding after its end is computed but
        masked out of the mean; it cannot reach earlier steps)."""
        syn = mem = out = None
        acc = 0.0
        full = x.shape[0] if lengths is None else int(lengths.min())
        if full < x.shape[0]:
            mask = (torch.arange(x.shape[0])[:, None] < lengths[None, :]).to(x.dtype)
            mask = mask.unsqueeze(-1)  # (steps, batch, 1)
        # unbind, not cur_all[t]: indexing's backward writes a whole (steps x batch x
        # hidden) zero tensor for each step, quadratic in the steps.
        cur_all = self.fc1(x).unbind(0) if self.hoist else None
        for t in range(x.shape[0]):
            cur = cur_all[t] if self.hoist else self.fc1(x[t])
            if syn is None:
                syn, mem = torch.zeros_like(cur), torch.zeros_like(cur)
                out = torch.zeros(cur.shape[0], self.classes, dtype=cur.dtype)
            spk, syn, mem = self.lif(cur, syn, mem)
            spk = spk.to(cur.dtype)  # fast_sigmoid's spikes are float32 whatever the input
            if self.reset == "manual":
                mem = mem * (1.0 - spk.detach())
            _, out = self.out(self.fc2(spk), out)
            acc = acc + (out if t < full else out * mask[t])
        return acc / (x.shape[0] if lengths is None else lengths[:, None].to(acc.dtype))


def part(x, lengths, which):
    """The recordings `which` of x, cut to the longest of them, and their lengths (None
    when all recordings have the same length)."""
    if lengths is None:
        return x[:, which], None
    return x[:int(lengths[which].max()), which], lengths[which]


def epoch(data, train, valid, reset, hoist, sigma, dtype, rng, gen, scale):
    """One `fit` with one epoch: a fresh network and Adam, the training batches, the
    validation loss."""
    x, y, lengths = data
    net = Net(reset, hoist, sigma, gen, x.shape[2], int(y.max()) + 1, scale).to(dtype)
    opt = torch.optim.Adam(net.parameters(), lr=LEARNING_RATE)
    loss_fn = nn.CrossEntropyLoss()
    order = rng.permutation(train)
    for start in range(0, len(order), BATCH):
        batch = order[start:start + BATCH]
        opt.zero_grad()
        loss = loss_fn(net(*part(x, lengths, batch)), y[batch])
        loss.backward()
        opt.step()
    with torch.no_grad():
        return loss_fn(net(*part(x, lengths, valid)), y[valid]).item()


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--dtype", choices=["float64", "float32", "both"], default="float64")
    ap.add_argument("--reset", choices=["manual", "delay", "nodelay"], default="manual")
    ap.add_argument("--hoist", action="store_true",
                    help="apply the input Linear to all steps at once before the time loop")
    ap.add_argument("--epochs", type=int, default=7, help="timed epochs (after 1 warm-up)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--inputs", metavar="DIR",
                    help="train on `neurotex export inputs`' folder instead of synthetic data")
    ap.add_argument("--standardize", choices=["on", "off"],
                    help="standardised inputs, as neurotex's default (default: on with "
                         "--inputs, off on the synthetic data, as it was measured)")
    args = ap.parse_args()
    torch.set_num_threads(args.threads)

    rng = np.random.default_rng(args.seed)
    if args.inputs:
        # Time-major already: (steps, recordings, inputs), zero-padded.
        x_tm, y_np, lengths_np, labels = exported(args.inputs)
        classes = len(labels)
    else:
        x_np, y_np = recordings(rng)
        x_tm, lengths_np, classes = x_np.transpose(1, 0, 2).copy(), None, CLASSES
    train, valid = validation_split(y_np, rng, classes)
    inputs = x_tm.shape[2]
    real = (np.full(len(y_np), x_tm.shape[0]) if lengths_np is None else lengths_np)
    cells = int(real.sum()) * inputs  # input x step cells, padding excluded
    spiking = float(np.count_nonzero(x_tm)) / cells
    per_step = float(x_tm.sum()) / cells
    rate = float(x_tm[:, train].sum()) / (int(real[train].sum()) * inputs)
    sigma = 1.0 / math.sqrt(inputs * rate * kernel_energy(ALPHA, BETA))
    standardize = (args.standardize or ("on" if args.inputs else "off")) == "on"
    scale = standardisation(x_tm, real, train) if standardize else None
    if scale is not None:
        # The data transform, once: z = (x - mean) / spread (padding too: masked out).
        x_tm = (x_tm - scale[0]) / scale[1]
    dtypes = ["float64", "float32"] if args.dtype == "both" else [args.dtype]
    for name in dtypes:
        dtype = getattr(torch, name)
        x = torch.from_numpy(x_tm).to(dtype)
        y = torch.from_numpy(y_np).long()
        lengths = None if lengths_np is None else torch.from_numpy(lengths_np)
        gen = torch.Generator().manual_seed(args.seed)
        times, losses = [], []
        for i in range(1 + args.epochs):
            t0 = time.perf_counter()
            loss = epoch((x, y, lengths), train, valid, args.reset, args.hoist, sigma, dtype,
                         rng, gen, scale)
            elapsed = (time.perf_counter() - t0) * 1e3
            if i > 0:
                times.append(elapsed)
                losses.append(loss)
        print(json.dumps({
            "peer": "snntorch",
            "of": f"inputs {args.inputs}" if args.inputs else "snn/train_epoch/55x32x1200",
            "median_ms": round(statistics.median(times), 2),
            "median_s": round(statistics.median(times) / 1e3, 3),
            "samples_ms": [round(t, 2) for t in times],
            "dtype": name, "reset": args.reset, "hoist": args.hoist,
            "standardize": standardize,
            "threads": torch.get_num_threads(),
            "recordings": len(y_np), "inputs": inputs, "hidden": HIDDEN, "classes": classes,
            "steps_min": int(real.min()), "steps_max": int(real.max()),
            "steps_mean": round(float(real.mean()), 1),
            "train": len(train), "valid": len(valid), "batch": BATCH,
            "input_cells_spiking": round(spiking, 4),
            "spikes_per_input_step": round(per_step, 4),
            "validation_loss_median": round(statistics.median(losses), 4),
            "torch": torch.__version__, "snntorch": snntorch.__version__,
        }), flush=True)


if __name__ == "__main__":
    main()
