#!/usr/bin/env python3
"""Every command's outputs in one folder, to check that a change leaves them byte-equal.

    tools/outputs_snapshot.sh BIN OUTDIR     # run the commands with the binary BIN
    tools/outputs_snapshot.sh --diff A B     # list what differs; exit 1 if anything does

The snapshot runs every user command (simulate, import csv, inspect, encode, features with
each method, evaluate with each classifier and the spiking network, train, predict, export
nir/xylo/inputs/events, compare, reproduce --quick, stream from a file) on a small simulated
dataset, and, when `../shared/data/fabricslide/fabric` exists beside the repository, on
FabricSlide (imported whole; the expensive commands on its 50 mm/s slides only). It takes
about a minute on two cores.

OUTDIR holds `commands.txt` (each step's command line and exit code), `stdout/` (each
step's standard output and error), `files/` (every file the commands wrote) and
`MANIFEST.sha256` (a sha256 per file). Text is normalised before it is stored and hashed,
so that two runs of one binary give identical snapshots; what is normalised, and why, is
listed at `NORMALISE`. The recordings of the simulated and imported datasets, and any file
over `COPY_LIMIT` bytes, are hashed but not copied. Nothing is normalised in binary files:
they must be equal as they are.
"""
import difflib
import hashlib
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile

ROOT = os.path.realpath(os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
FABRIC = os.path.realpath(os.path.join(ROOT, "..", "shared", "data", "fabricslide", "fabric"))
COPY_LIMIT = 2 * 1024 * 1024
# The datasets simulate and import write: their recordings are hashed, not copied (150 MB).
DATASETS = ("sim", "fab", "fab50")
STEP_TIMEOUT_S = 600
SHOWN_DIFFS = 10
SIM = ["simulate", "--out", "sim", "--seed", "7", "--trials", "4"]
FABRIC_LOGS = ["--time-column", "timestamp", "--channels", r"^channel\d+$"]
FABRIC_IMPORT = ["--name-pattern", "{label}_F{force}_V{speed}mmps_{trial}.csv"] + FABRIC_LOGS
METHODS = ["taxel", "all-taxels", "all-taxels-mm", "glcm2d", "glcm3d", "glcm3d-multi", "spectrum"]
SNN = ["--classifier", "snn", "--snn-epochs", "3", "--snn-hidden", "16"]


def sim_steps():
    """(name, arguments) of the commands on the simulated dataset, in order."""
    steps = [("simulate", SIM),
             ("inspect-sim", ["inspect", "sim", "--out", "out/inspect-sim"]),
             ("inspect-sim-json", ["inspect", "sim", "--json", "--no-encoder"]),
             ("encode-sim", ["encode", "sim/FT1_v5_t00.npy", "--out", "out/encode-sim.npy"])]
    steps += [(f"features-{m}", ["features", "--dataset", "sim", "--method", m,
                                 "--out", f"out/features-{m}.csv"]) for m in METHODS]
    steps += [("features-sa+fa", ["features", "--dataset", "sim", "--method", "glcm3d",
                                  "--encoding", "sa+fa", "--out", "out/features-sa+fa.csv"]),
              ("features-stdout", ["features", "--dataset", "sim", "--method", "glcm2d",
                                   "--out", "-"])]
    evaluate = ["evaluate", "--dataset", "sim"]
    steps += [("evaluate-knn", evaluate + ["--method", "taxel"]),
              ("evaluate-knn-json", evaluate + ["--method", "glcm3d", "--json",
                                                "--predictions", "out/eval-knn.csv"]),
              ("evaluate-forest", evaluate + ["--method", "glcm3d", "--classifier", "forest",
                                              "--trees", "20"]),
              ("evaluate-linear", evaluate + ["--method", "all-taxels", "--classifier",
                                              "linear"]),
              ("evaluate-speeds", evaluate + ["--method", "glcm3d", "--train-speeds", "5,10",
                                              "--test-speeds", "15"]),
              ("evaluate-van-rossum", evaluate + ["--method", "van-rossum", "--folds", "3"]),
              ("evaluate-snn", evaluate + ["--method", "spikes"] + SNN + ["--folds", "3", "--json"])]
    steps += model_steps("sim", "sim")
    steps += [("compare-sim", ["compare", "--dataset", "sim", "--folds", "3", "--repeats", "1",
                               "--out", "out/compare-sim"]),
              ("compare-sim-nested", ["compare", "--dataset", "sim", "--folds", "3",
                                      "--repeats", "1", "--methods", "taxel,glcm3d",
                                      "--classifiers", "knn,linear", "--nested", "--json"]),
              ("reproduce-sim", ["reproduce", "--quick", "--dataset", "sim",
                                 "--out", "out/report-sim"]),
              ("stream-sim-csv", ["stream", "--model", "out/model-causal-sim.json",
                                  "--input", "out/sim-frames.csv", "--no-header"]),
              ("stream-sim-events", ["stream", "--model", "out/model-knn-sim.json",
                                     "--input", "out/events-sim/00000_FT1_v5_t00.csv",
                                     "--format", "events", "--time-unit", "ms"])]
    return steps


def model_steps(dataset, tag):
    """Train, predict and export on `dataset`, outputs named with `tag`."""
    model, causal, snn, xylo = (f"out/model-{kind}-{tag}.json"
                                for kind in ("knn", "causal", "snn", "xylo"))
    predict = ["predict", "--dataset", dataset, "--json", "--model"]
    return [
        (f"train-knn-{tag}", ["train", "--dataset", dataset, "--method", "glcm3d", "--out", model]),
        (f"predict-knn-{tag}", predict + [model, "--out", f"out/predict-knn-{tag}.csv"]),
        (f"train-causal-{tag}", ["train", "--dataset", dataset, "--method", "glcm3d",
                                 "--causal", "--out", causal]),
        (f"predict-causal-{tag}", ["predict", "--model", causal, "--dataset", dataset,
                                   "--causal", "--out", f"out/predict-causal-{tag}.jsonl"]),
        (f"train-snn-{tag}", ["train", "--dataset", dataset] + SNN + ["--out", snn]),
        (f"predict-snn-{tag}", predict + [snn, "--out", f"out/predict-snn-{tag}.csv"]),
        (f"export-nir-{tag}", ["export", "nir", "--model", snn, "--out", f"out/net-{tag}.nir"]),
        (f"export-nir-snntorch-{tag}", ["export", "nir", "--model", snn, "--for", "snntorch",
                                        "--out", f"out/net-snntorch-{tag}.nir"]),
        (f"predict-nir-{tag}", predict + [f"out/net-{tag}.nir", "--out",
                                          f"out/predict-nir-{tag}.csv"]),
        (f"export-inputs-{tag}", ["export", "inputs", "--model", snn, "--dataset", dataset,
                                  "--out", f"out/inputs-{tag}"]),
        (f"train-xylo-{tag}", ["train", "--dataset", dataset] + SNN
         + ["--snn-target", "xylo", "--out", xylo]),
        (f"predict-xylo-{tag}", predict + [xylo, "--out", f"out/predict-xylo-{tag}.csv"]),
        (f"export-xylo-{tag}", ["export", "xylo", "--model", xylo, "--out", f"out/xylo-{tag}.json"]),
        (f"export-events-{tag}", ["export", "events", "--dataset", dataset,
                                  "--out", f"out/events-{tag}"]),
    ]


def fabric_steps():
    """(name, arguments) of the commands on FabricSlide; its 50 mm/s slides for most."""
    logs = sorted(f for f in os.listdir(FABRIC) if "_V50mmps_" in f)
    first = os.path.join(FABRIC, logs[0])
    imported = FABRIC_IMPORT + ["--grid", "4x4", "--baseline", "min"]
    steps = [("import-fabric", ["import", "csv", FABRIC] + imported + ["--out", "fab"]),
             ("import-fabric-50", ["import", "csv"] + [os.path.join(FABRIC, f) for f in logs]
              + imported + ["--out", "fab50"]),
             ("inspect-fabric", ["inspect", "fab", "--out", "out/inspect-fabric"]),
             ("inspect-fabric-logs", ["inspect", first] + FABRIC_IMPORT + ["--no-encoder"]),
             ("encode-fabric", ["encode", first] + FABRIC_LOGS
              + ["--grid", "4x4", "--out", "out/encode-fabric.npy"])]
    steps += [(f"features-fabric-{m}", ["features", "--dataset", "fab50", "--method", m,
                                        "--out", f"out/features-fabric-{m}.csv"])
              for m in METHODS]
    evaluate = ["evaluate", "--dataset", "fab", "--speeds", "50"]
    steps += [("evaluate-fabric-knn", evaluate + ["--method", "glcm3d", "--json"]),
              ("evaluate-fabric-taxel", evaluate + ["--method", "taxel"]),
              ("evaluate-fabric-forest", evaluate + ["--method", "glcm3d", "--classifier",
                                                     "forest", "--trees", "20"]),
              ("evaluate-fabric-linear", evaluate + ["--method", "all-taxels", "--classifier",
                                                     "linear"]),
              ("evaluate-fabric-snn", evaluate + ["--method", "spikes"] + SNN + ["--folds", "3"])]
    steps += model_steps("fab50", "fabric")
    steps += [("compare-fabric", ["compare", "--dataset", "fab", "--speeds", "50",
                                  "--methods", "taxel,glcm3d,spectrum", "--classifiers",
                                  "knn,forest", "--folds", "3", "--repeats", "1",
                                  "--out", "out/compare-fabric"]),
              ("reproduce-fabric", ["reproduce", "--quick", "--dataset", "fab50",
                                    "--out", "out/report-fabric"]),
              ("stream-fabric-csv", ["stream", "--model", "out/model-causal-fabric.json",
                                     "--input", first] + FABRIC_LOGS)]
    return steps


def npy_to_csv(npy, csv):
    """A float32 `(T, rows, cols)` recording as headerless CSV frames, for `stream`."""
    data = open(npy, "rb").read()
    header_len = struct.unpack("<H", data[8:10])[0]
    header = data[10:10 + header_len].decode("latin1")
    assert "'<f4'" in header and "False" in header, header
    dims = [int(d) for d in re.search(r"\((.*?)\)", header).group(1).split(",") if d.strip()]
    width = 1
    for d in dims[1:]:
        width *= d
    values = struct.unpack(f"<{dims[0] * width}f", data[10 + header_len:])
    with open(csv, "w") as out:
        for t in range(dims[0]):
            out.write(",".join(repr(v) for v in values[t * width:(t + 1) * width]) + "\n")


# Timing and provenance that change from run to run (or from commit to commit) and say
# nothing of the results: each is replaced by a placeholder. Each pattern is anchored to
# the words around it, so a number of the results is never caught.
NORMALISE = [
    # Progress on standard error. A step's count (`[  1.2 s] recordings 48/96`) is printed
    # at intervals of wall-clock time, so which counts appear varies: those lines are
    # dropped. The others keep their words (`[   0.0 s] encoding (96 steps)`).
    (re.compile(r"^\[\s*\d+(\.\d+)? s\] .* \d+/\d+\n", re.M), ""),
    (re.compile(r"\[\s*\d+(\.\d+)? s\]"), "[<T> s]"),
    # Elapsed time at the end of a line: `report in out/r/report.md (4.5 s)`, `(0.2 s)`.
    (re.compile(r"\(\d+(\.\d+)? (s|ms)\)"), r"(<T> \2)"),
    # The report's first paragraph: `its analyses took 1.6 s`.
    (re.compile(r"(its analyses took )\d+(\.\d+)? s"), r"\1<T> s"),
    # JSON timings (compare's candidates, reproduce's analyses) and the date of a run.
    (re.compile(r'("[a-z_]*seconds[a-z_]*"\s*:\s*)[-0-9.eE+]+'), r'\1"<T>"'),
    (re.compile(r'("created_utc"\s*:\s*)"[^"]*"'), r'\1"<DATE>"'),
    # The build's commit: two builds of one tree from different commits give the same
    # outputs, and this is what the snapshot compares.
    (re.compile(r'("git_commit"\s*:\s*)"[0-9a-f]*"'), r'\1"<COMMIT>"'),
    (re.compile(r"(commit `?)[0-9a-f]{7,40}"), r"\1<COMMIT>"),
    # Dates and times written into reports (`2026-11-28T12:00:00Z`).
    (re.compile(r"\d{4}-\d\d-\d\dT\d\d:\d\d:\d\dZ"), "<DATE>"),
    # reproduce's wall clock per analysis: results.json's `timing_s` and the report's list.
    (re.compile(r'"timing_s"\s*:\s*\{[^{}]*\}'),
     lambda m: re.sub(r'(":\s*)-?\d[0-9.eE+-]*', r'\1"<T>"', m.group(0))),
    (re.compile(r"^## Timing \(wall clock, s\)\n(\n|- .*: [0-9.]+\n)*", re.M),
     lambda m: re.sub(r": [0-9.]+\n", ": <T>\n", m.group(0))),
]


# compare's seconds per candidate, the last column of its ranking (text lines on standard
# output, a Markdown table in compare.md): only in compare's outputs, whose names say so.
COMPARE_SECONDS = [
    (re.compile(r"^( *\d+\. .*\s)\d+(\.\d+)? s$", re.M), r"\1<T> s"),
    (re.compile(r"^(\| \d+ \|.*\| )\d+(\.\d+)? \|$", re.M), r"\1<T> |"),
]


def normalise(text, work, name):
    """`text` of the output `name` with run-dependent parts replaced (the lists above, and
    the temporary folder's absolute path, which differs on every run; FabricSlide's and the
    repository's paths, which differ between checkouts)."""
    for path, placeholder in ((work, "<WORK>"), (FABRIC, "<FABRIC>"), (ROOT, "<REPO>")):
        text = text.replace(path, placeholder)
    rules = NORMALISE + (COMPARE_SECONDS if "compare" in name else [])
    for pattern, replacement in rules:
        text = pattern.sub(replacement, text)
    return text


def as_text(data):
    """`data` decoded when it is UTF-8 text without NUL bytes, else None."""
    if b"\0" in data:
        return None
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return None


def output_record(text, folder):
    """A folder's `.neurotex-output` record (`sha256  name` lines) with each hash replaced
    by whether it matches the file: the files' own normalised hashes are in the manifest,
    and a raw hash would differ wherever a file's timings do."""
    lines = []
    for line in text.splitlines():
        digest, _, name = line.partition("  ")
        path = os.path.join(folder, name)
        ok = os.path.isfile(path) and sha256(open(path, "rb").read()) == digest
        lines.append(f"{'matches' if ok else 'DIFFERS'}  {name}")
    return "\n".join(lines) + "\n"


def sha256(data):
    return hashlib.sha256(data).hexdigest()


def run_steps(binary, work, out, steps):
    """Runs each step in `work`, storing its normalised standard output and error."""
    log = []
    for i, (name, args) in enumerate(steps, 1):
        stem = f"{i:02d}-{name}"
        # `stream` reads text frames: one simulated recording written as CSV, by this script.
        if name == "stream-sim-csv":
            npy_to_csv(os.path.join(work, "sim", "FT1_v5_t00.npy"),
                       os.path.join(work, "out", "sim-frames.csv"))
        try:
            done = subprocess.run([binary] + args, cwd=work, capture_output=True,
                                  timeout=STEP_TIMEOUT_S)
            code, stdout, stderr = done.returncode, done.stdout, done.stderr
        except subprocess.TimeoutExpired:
            code, stdout, stderr = "timeout", b"", b""
        for suffix, data in (("out", stdout), ("err", stderr)):
            text = as_text(data)
            data = data if text is None else normalise(text, work, name).encode()
            with open(os.path.join(out, "stdout", f"{stem}.{suffix}"), "wb") as f:
                f.write(data)
        line = normalise(" ".join(["neurotex"] + args), work, name)
        log.append(f"{stem}: exit {code}: {line}")
        print(f"  {stem}: exit {code}", file=sys.stderr)
    return log


def store_files(work, out):
    """Copies every file the commands wrote into `out/files`, normalised; returns the
    manifest's entries for the large ones, hashed in place."""
    large = []
    for folder, _, files in sorted(os.walk(work)):
        for f in sorted(files):
            path = os.path.join(folder, f)
            rel = os.path.relpath(path, work)
            data = open(path, "rb").read()
            text = as_text(data)
            if f == ".neurotex-output" and text is not None:
                text = output_record(text, folder)
            if text is not None:
                data = normalise(text, work, rel).encode()
            recording = rel.split(os.sep)[0] in DATASETS and f not in ("manifest.csv",
                                                                        "layout.toml")
            if len(data) > COPY_LIMIT or recording:
                large.append(f"{sha256(data)}  files/{rel} (not copied: {len(data)} bytes)")
                continue
            target = os.path.join(out, "files", rel)
            os.makedirs(os.path.dirname(target), exist_ok=True)
            with open(target, "wb") as g:
                g.write(data)
    return large


def snapshot(binary, out):
    binary = os.path.realpath(binary)
    if os.path.exists(out) and os.listdir(out):
        sys.exit(f"{out} exists and is not empty")
    os.makedirs(os.path.join(out, "stdout"), exist_ok=True)
    steps = sim_steps()
    if os.path.isdir(FABRIC):
        steps += fabric_steps()
    else:
        print(f"no FabricSlide at {FABRIC}: simulated data only", file=sys.stderr)
    work = os.path.realpath(tempfile.mkdtemp(prefix="neurotex-snapshot-"))
    try:
        os.makedirs(os.path.join(work, "out"))
        log = run_steps(binary, work, out, steps)
        large = store_files(work, out)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    with open(os.path.join(out, "commands.txt"), "w") as f:
        f.write("\n".join(log) + "\n")
    entries = large
    for folder, _, files in os.walk(out):
        for f in files:
            path = os.path.join(folder, f)
            rel = os.path.relpath(path, out)
            if rel != "MANIFEST.sha256":
                entries.append(f"{sha256(open(path, 'rb').read())}  {rel}")
    with open(os.path.join(out, "MANIFEST.sha256"), "w") as f:
        f.write("\n".join(sorted(entries, key=lambda e: e.split("  ", 1)[1])) + "\n")
    failed = [line for line in log if ": exit 0:" not in line]
    print(f"{len(steps)} commands, {len(entries)} files -> {out}", file=sys.stderr)
    for line in failed:
        print(f"  failed: {line}", file=sys.stderr)
    return 0


def manifest(folder):
    entries = {}
    for line in open(os.path.join(folder, "MANIFEST.sha256")):
        digest, _, rel = line.rstrip("\n").partition("  ")
        entries[rel.split(" (not copied")[0]] = digest
    return entries


def diff(a, b):
    """Lists the files that differ between snapshots `a` and `b`, with the first lines of a
    text diff for the first few; 1 when anything differs."""
    ma, mb = manifest(a), manifest(b)
    differs = 0
    for rel in sorted(set(ma) | set(mb)):
        if rel not in mb or rel not in ma:
            print(f"only in {a if rel in ma else b}: {rel}")
        elif ma[rel] != mb[rel]:
            print(f"differs: {rel}")
            paths = [os.path.join(x, rel) for x in (a, b)]
            # The first lines of a text diff for the first few files, enough to see why.
            if differs < SHOWN_DIFFS and all(os.path.isfile(p) for p in paths):
                texts = [as_text(open(p, "rb").read()) for p in paths]
                if None not in texts:
                    lines = difflib.unified_diff(texts[0].splitlines(), texts[1].splitlines(),
                                                 paths[0], paths[1], lineterm="", n=1)
                    for line in list(lines)[:20]:
                        print(f"    {line}")
        else:
            continue
        differs += 1
    print(f"{differs} file(s) differ" if differs else "snapshots are identical")
    return 1 if differs else 0


def main(argv):
    if len(argv) == 3 and argv[0] == "--diff":
        return diff(argv[1], argv[2])
    if len(argv) == 2 and not argv[0].startswith("-"):
        return snapshot(argv[0], argv[1])
    print(__doc__, file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
