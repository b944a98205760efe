# Sourced by run.sh and xylo.sh.
#
# `make_venv DIR REQUIREMENTS...`: a virtual environment with CPU torch and the
# requirements, made once (DIR/.installed marks it done).
#
# `subset SRC DEST COND` makes dataset folder DEST of the
# recordings of dataset SRC whose manifest row meets the awk condition COND on the trial
# `t` and speed `v` (hard links where possible, copies otherwise).
subset() {
    local src=$1 dest=$2 cond=$3
    mkdir -p "$dest"
    [ -f "$src/layout.toml" ] && cp "$src/layout.toml" "$dest/"
    head -1 "$src/manifest.csv" > "$dest/manifest.csv"
    local cols; cols=$(head -1 "$src/manifest.csv" | tr -d '\r' | tr ',' '\n')
    local tc vc
    tc=$(echo "$cols" | grep -n '^trial$' | cut -d: -f1)
    vc=$(echo "$cols" | grep -n '^speed_mm_s$' | cut -d: -f1)
    tail -n +2 "$src/manifest.csv" | awk -F, -v tc="$tc" -v vc="$vc" \
        "{ t = \$tc + 0; v = \$vc + 0; if ($cond) print }" >> "$dest/manifest.csv"
    tail -n +2 "$dest/manifest.csv" | cut -d, -f1 | while read -r f; do
        mkdir -p "$dest/$(dirname "$f")"; ln "$src/$f" "$dest/$f" 2>/dev/null || cp "$src/$f" "$dest/$f"
    done
}

make_venv() { # dir, pip requirements...
    local dir=$1; shift
    [ -e "$dir/.installed" ] && return
    echo "creating $dir (torch is large: minutes)" >&2
    rm -rf "$dir"; python3 -m venv "$dir"
    "$dir/bin/pip" install -q --upgrade pip
    # The CPU-only wheels when their index is reachable; else PyPI's (CUDA libraries
    # included, about 5 GB, and they run on a CPU too).
    "$dir/bin/pip" install -q --index-url https://download.pytorch.org/whl/cpu torch ||
        "$dir/bin/pip" install -q torch
    "$dir/bin/pip" install -q "$@"
    touch "$dir/.installed"
}
