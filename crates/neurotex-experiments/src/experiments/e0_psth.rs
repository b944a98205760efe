//! E0: one taxel's PSTH and the whole rate volume for two textures at the slowest speed:
//! the volumes differ more than the PSTHs (paper figure 3).

use serde::{Deserialize, Serialize};

use super::{Context, Stop};
use crate::features::RateVolume;
use crate::values::{Grid, Speed};

/// E0: one taxel's PSTH and the rate volume, for two textures.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E0 {
    /// Speed, mm/s.
    pub speed: Speed,
    /// The taxel shown, `[row, col]`.
    pub taxel: [usize; 2],
    /// PSTH bin, ms.
    pub psth_bin_ms: usize,
    /// Per texture.
    pub examples: Vec<E0Example>,
}

/// One texture's example for E0.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct E0Example {
    /// Texture label.
    pub label: String,
    /// Recording file.
    pub file: String,
    /// Spike counts of the taxel per PSTH bin.
    pub psth: Vec<u32>,
    /// Rate volume, `cells x bins` (row-major cells), Hz.
    pub volume: Vec<Vec<f64>>,
}

/// E0 for the paper's pair (scotch brite and styrofoam) when present, else the first two
/// labels, on the first recording of each at the slowest speed.
///
/// # Errors
/// None of its own.
pub fn e0_psth(c: &Context) -> Result<E0, Stop> {
    let labels = &c.prepared.labels;
    let pick = |want: &str| labels.iter().find(|l| l.eq_ignore_ascii_case(want));
    let chosen: Vec<&String> = match (pick("SB"), pick("STF")) {
        (Some(a), Some(b)) => vec![a, b],
        _ => labels.iter().take(2).collect(),
    };
    let grid = &c.prepared.grid;
    let cell = shown_taxel(grid);
    let bin = c.params.pipeline.volume.bin_ms;
    let examples = chosen
        .iter()
        .filter_map(|&label| {
            c.prepared
                .at(c.prepared.slowest)
                .find(|e| &e.meta.label == label)
        })
        .map(|e| {
            let mut psth = vec![0u32; e.spikes.n_steps.div_ceil(bin)];
            for &t in e.spikes.train(cell) {
                psth[t as usize / bin] += 1;
            }
            let volume = RateVolume::from_spikes(&e.spikes, bin)
                .map(|v| v.data.chunks(v.bins).map(|c| c.to_vec()).collect())
                .unwrap_or_default();
            E0Example {
                label: e.meta.label.clone(),
                file: e.meta.file.clone(),
                psth,
                volume,
            }
        })
        .collect();
    let shown = grid.cell(cell);
    Ok(E0 {
        speed: c.prepared.slowest,
        taxel: [shown.row, shown.col],
        psth_bin_ms: bin,
        examples,
    })
}

/// The taxel at row 1, column 1 when the grid has it (an inner taxel of the paper's 4x4),
/// else the first taxel.
fn shown_taxel(grid: &Grid) -> usize {
    let inner = grid.cols() + 1;
    if grid.cells() > inner && grid.present()[inner] {
        inner
    } else {
        grid.taxels().next().unwrap_or(0)
    }
}

#[cfg(test)]
mod tests {
    use super::super::testing::small_run;
    use super::*;

    #[test]
    fn psth_counts_are_the_taxels_spikes_and_the_volume_covers_the_grid() {
        let run = small_run();
        let c = run.context();
        let e0 = e0_psth(&c).unwrap();
        assert_eq!(e0.taxel, [1, 1]);
        let labels: Vec<&str> = e0.examples.iter().map(|e| e.label.as_str()).collect();
        assert_eq!(labels, ["SB", "STF"]);
        for ex in &e0.examples {
            let rec = c
                .prepared
                .encoded
                .iter()
                .find(|e| e.meta.file == ex.file)
                .unwrap();
            let cell = c.prepared.grid.cols() + 1;
            assert_eq!(
                ex.psth.iter().sum::<u32>() as usize,
                rec.spikes.train(cell).len()
            );
            assert_eq!(ex.volume.len(), c.prepared.grid.cells());
        }
        let masked = Grid::masked(2, 2, vec![false, true, true, false]).unwrap();
        assert_eq!(shown_taxel(&masked), 1);
    }
}
