//! The feature extractor: an encoded recording's spike trains become its feature row, by
//! the method asked for, on the grid the extractor was planned for.

use super::{
    spectrum_names, spectrum_span, taxel_cells, too_short, Encoded, Encoding, FeatureParams,
    HaralickSet, Method, PipelineParams, NO_SPEED,
};
use crate::encode::SpikeTrains;
use crate::error::{DataError, ParamError, Result};
use crate::features::glcm::GlcmKind;
use crate::features::{
    distance_stats, haralick, haralick_full, spike_stats, CountVolume, GlcmParams, GlcmPlan,
    Spectrum, VolumeParams, FULL_NAMES,
};
use crate::values::Grid;

/// One population's 3D-GLCM gray levels, `cell * bins + bin`, as the extractor quantises
/// its rate volume (kept by E3, which counts them again with taxels moved).
pub struct Quantised {
    levels: Vec<u8>,
    bins: usize,
}

/// Turns spike trains into feature rows, with the GLCM offsets planned once for a grid.
#[derive(Debug, Clone)]
pub struct FeatureExtractor {
    volume: VolumeParams,
    glcm: GlcmParams,
    encoding: Encoding,
    features: FeatureParams,
    grid: Grid,
    plan3d: GlcmPlan,
    plan2d: GlcmPlan,
    spectrum: Spectrum,
}

impl FeatureExtractor {
    /// Plans the extractor for `grid`.
    ///
    /// # Errors
    /// A broken parameter rule.
    pub fn new(params: &PipelineParams, grid: &Grid) -> Result<Self, ParamError> {
        params.volume.check()?;
        params.features.check()?;
        let levels = params.volume.levels;
        let (rows, cols, present) = (grid.rows(), grid.cols(), grid.present());
        Ok(FeatureExtractor {
            volume: params.volume.clone(),
            glcm: params.glcm.clone(),
            encoding: params.encoding,
            features: params.features.clone(),
            grid: grid.clone(),
            plan3d: GlcmPlan::new(rows, cols, present, levels, &params.glcm, GlcmKind::ThreeD)?,
            plan2d: GlcmPlan::new(rows, cols, present, levels, &params.glcm, GlcmKind::TwoD)?,
            spectrum: Spectrum::new(params.features.spectrum()),
        })
    }

    /// The grid the extractor was planned for.
    pub fn grid(&self) -> &Grid {
        &self.grid
    }

    /// The encoding whose populations the rows hold.
    pub fn encoding(&self) -> Encoding {
        self.encoding
    }

    /// Column names of `method`'s features for this grid: one population's names, each
    /// population's prefixed with `sa_` / `fa_` for the `sa+fa` encoding.
    pub fn names(&self, method: Method) -> Vec<String> {
        let one = self.population_names(method);
        self.encoding
            .prefixes()
            .iter()
            .flat_map(|prefix| one.iter().map(move |n| format!("{prefix}{n}")))
            .collect()
    }

    /// One population's column names.
    fn population_names(&self, method: Method) -> Vec<String> {
        let haralick: Vec<&str> = match self.features.haralick {
            HaralickSet::Paper => vec!["contrast", "correlation", "asm"],
            HaralickSet::Full => FULL_NAMES.to_vec(),
        };
        let per_taxel = |stats: &[&str]| -> Vec<String> {
            self.grid
                .taxels()
                .flat_map(|cell| {
                    let cell = self.grid.cell(cell);
                    stats.iter().map(move |f| format!("{cell}_{f}"))
                })
                .collect()
        };
        match method {
            Method::Taxel | Method::AllTaxels => per_taxel(&["msr", "cv_isi", "fano"]),
            Method::AllTaxelsMm => per_taxel(&["spikes_per_mm", "cv_isi", "fano_mm"]),
            Method::Rates => per_taxel(&["msr"]),
            Method::Glcm2d | Method::Glcm3d => haralick.iter().map(|h| h.to_string()).collect(),
            Method::Glcm3dMulti => self
                .features
                .bin_widths_ms
                .iter()
                .flat_map(|w| haralick.iter().map(move |h| format!("{w}ms_{h}")))
                .collect(),
            Method::Spectrum => spectrum_names(&self.grid, &self.features),
        }
    }

    /// The feature row of one encoded recording: each population's features in the order
    /// of [`Encoded::populations`], as many populations as the extractor's encoding has.
    ///
    /// # Errors
    /// The trains are shorter than one bin; a population the encoding needs is missing;
    /// [`Method::AllTaxelsMm`] on a recording without a nonzero speed.
    pub fn row(&self, encoded: &Encoded, method: Method) -> Result<Vec<f64>> {
        let populations = self.populations(encoded)?;
        let speed = encoded
            .meta
            .speed_mm_s
            .filter(|s| s.is_finite() && *s != 0.0);
        if method == Method::AllTaxelsMm && speed.is_none() {
            return Err(DataError::invalid(&encoded.meta.file, NO_SPEED).into());
        }
        if method == Method::Spectrum {
            let span = spectrum_span(encoded.spikes.n_steps, speed, &self.features);
            span.map_err(|why| DataError::invalid(&encoded.meta.file, why))?;
        }
        let mut row = Vec::new();
        for spikes in populations {
            row.extend(self.population_row(spikes, speed, method)?);
        }
        Ok(row)
    }

    /// The populations of `encoded` the extractor's encoding reads.
    ///
    /// # Errors
    /// A population the encoding needs is missing.
    fn populations<'a>(&self, encoded: &'a Encoded) -> Result<Vec<&'a SpikeTrains>> {
        let wanted = self.encoding.prefixes().len();
        let populations: Vec<&SpikeTrains> = encoded.populations().take(wanted).collect();
        if populations.len() < wanted {
            return Err(DataError::invalid(
                &encoded.meta.file,
                format!(
                    "the {} encoding needs two populations; the recording was encoded with one",
                    self.encoding.name()
                ),
            )
            .into());
        }
        Ok(populations)
    }

    /// Each population's 3D-GLCM gray levels of `encoded` (see [`Quantised`]), for
    /// [`FeatureExtractor::glcm3d_moved`].
    ///
    /// # Errors
    /// As [`FeatureExtractor::row`] with [`Method::Glcm3d`].
    pub fn quantised_3d(&self, encoded: &Encoded) -> Result<Vec<Quantised>> {
        self.populations(encoded)?
            .into_iter()
            .map(|spikes| {
                if !self.on_grid(spikes) {
                    let message = "its taxel grid differs from the extractor's";
                    return Err(DataError::invalid(&encoded.meta.file, message).into());
                }
                let bin = self.volume.bin_ms;
                let volume =
                    CountVolume::from_spikes(spikes, bin).ok_or_else(|| too_short(spikes, bin))?;
                self.check_bins(&self.plan3d, volume.bins)?;
                let mut levels = Vec::new();
                volume.quantise(self.volume.levels, self.volume.range, &mut levels);
                Ok(Quantised {
                    levels,
                    bins: volume.bins,
                })
            })
            .collect()
    }

    /// The [`Method::Glcm3d`] row of a recording whose taxels were moved: cell `from`'s
    /// gray levels go to cell `perm[from]`. The same as the row of the recording's spike
    /// trains moved by [`SpikeTrains::permuted`] (binning and quantising do not depend on
    /// where a cell is), without copying and binning the trains again.
    ///
    /// # Errors
    /// A permutation that is not one of the grid's cells, or that moves a taxel onto a
    /// cell without one.
    pub fn glcm3d_moved(&self, quantised: &[Quantised], perm: &[usize]) -> Result<Vec<f64>> {
        let present = self.grid.present();
        let keeps_taxels = perm.len() == present.len()
            && perm
                .iter()
                .enumerate()
                .all(|(from, &to)| to < present.len() && present[from] == present[to]);
        if !keeps_taxels {
            let rule = "a permutation of the grid's cells that keeps taxels on taxel cells";
            return Err(ParamError::new("perm", rule, format!("{perm:?}")).into());
        }
        let l = self.volume.levels;
        let mut row = Vec::new();
        let mut moved = Vec::new();
        for q in quantised {
            moved.clear();
            moved.resize(q.levels.len(), 0);
            for (from, &to) in perm.iter().enumerate() {
                moved[to * q.bins..(to + 1) * q.bins]
                    .copy_from_slice(&q.levels[from * q.bins..(from + 1) * q.bins]);
            }
            let mut counts = vec![0u64; l * l];
            self.plan3d.count_wide(&moved, q.bins, &mut counts);
            row.extend(self.haralick_row(&counts));
        }
        Ok(row)
    }

    /// Whether `spikes` are on the grid the extractor's GLCM offsets were planned for.
    fn on_grid(&self, spikes: &SpikeTrains) -> bool {
        (spikes.rows, spikes.cols) == (self.grid.rows(), self.grid.cols())
            && spikes.present == self.grid.present()
    }

    /// The error for a volume of more time bins than the plan's counts hold.
    fn check_bins(&self, plan: &GlcmPlan, bins: usize) -> Result<()> {
        if plan.counts_fit_wide(bins) {
            return Ok(());
        }
        Err(DataError::TooLarge {
            what: "the time bins of this recording's rate volume",
            got: bins as u64,
            limit: crate::features::glcm::MAX_SLICE_PAIRS,
            hint: "use a shorter recording or a wider --bin-ms",
        }
        .into())
    }

    /// One population's features; `speed_mm_s` is the recording's, for
    /// [`Method::AllTaxelsMm`].
    ///
    /// # Errors
    /// The trains are shorter than one bin, or [`Method::AllTaxelsMm`] without a nonzero
    /// speed.
    pub fn population_row(
        &self,
        spikes: &SpikeTrains,
        speed_mm_s: Option<f64>,
        method: Method,
    ) -> Result<Vec<f64>> {
        let bin = self.volume.bin_ms;
        if spikes.n_steps < bin {
            return Err(too_short(spikes, bin));
        }
        let n = spikes.n_steps;
        match method {
            Method::Taxel | Method::AllTaxels => Ok(taxel_cells(&spikes.present)
                .flat_map(|cell| spike_stats(spikes.train(cell), n, bin).to_array())
                .collect()),
            Method::Rates => Ok(taxel_cells(&spikes.present)
                .map(|cell| spike_stats(spikes.train(cell), n, bin).msr)
                .collect()),
            Method::AllTaxelsMm => {
                let speed = speed_mm_s
                    .filter(|s| s.is_finite() && *s != 0.0)
                    .ok_or_else(|| ParamError::new("speed", NO_SPEED, "none"))?;
                let window = self.features.window_mm;
                Ok(taxel_cells(&spikes.present)
                    .flat_map(|cell| {
                        distance_stats(spikes.train(cell), n, speed, window).to_array()
                    })
                    .collect())
            }
            Method::Glcm2d => self.glcm_features(spikes, GlcmKind::TwoD, bin),
            Method::Glcm3d => self.glcm_features(spikes, GlcmKind::ThreeD, bin),
            Method::Glcm3dMulti => {
                let mut row = Vec::new();
                for &width in &self.features.bin_widths_ms {
                    row.extend(self.glcm_features(spikes, GlcmKind::ThreeD, width)?);
                }
                Ok(row)
            }
            Method::Spectrum => {
                let span = spectrum_span(n, speed_mm_s, &self.features)
                    .map_err(|why| DataError::invalid("the recording", why))?;
                let mut row = Vec::new();
                for cell in taxel_cells(&spikes.present) {
                    self.spectrum.train(spikes.train(cell), span, &mut row);
                }
                Ok(row)
            }
        }
    }

    /// The Haralick features of the mean GLCM of the rate volume with bins of `bin_ms`
    /// (3D) or of the time-collapsed image (2D).
    fn glcm_features(
        &self,
        spikes: &SpikeTrains,
        kind: GlcmKind,
        bin_ms: usize,
    ) -> Result<Vec<f64>> {
        let volume = match kind {
            GlcmKind::ThreeD => CountVolume::from_spikes(spikes, bin_ms),
            GlcmKind::TwoD => CountVolume::collapsed(spikes),
        }
        .ok_or_else(|| too_short(spikes, bin_ms))?;
        let replanned;
        let plan = match (self.on_grid(spikes), kind) {
            (true, GlcmKind::ThreeD) => &self.plan3d,
            (true, GlcmKind::TwoD) => &self.plan2d,
            (false, _) => {
                replanned = GlcmPlan::new(
                    spikes.rows,
                    spikes.cols,
                    &spikes.present,
                    self.volume.levels,
                    &self.glcm,
                    kind,
                )?;
                &replanned
            }
        };
        self.check_bins(plan, volume.bins)?;
        if plan.counted_pairs(volume.bins) == 0 {
            return Err(no_pairs(&self.glcm.distances, spikes, kind, volume.bins).into());
        }
        let mut q = Vec::new();
        volume.quantise(self.volume.levels, self.volume.range, &mut q);
        let l = self.volume.levels;
        // u64 counts: a long volume with many distances passes u32's 4.3 billion pairs;
        // below it the u32 kernels count and the result is widened.
        let mut counts = vec![0u64; l * l];
        plan.count_wide(&q, volume.bins, &mut counts);
        Ok(self.haralick_row(&counts))
    }

    /// The Haralick features of the extractor's set from a GLCM's summed counts
    /// (`levels x levels`).
    pub fn haralick_row(&self, counts: &[u64]) -> Vec<f64> {
        let l = self.volume.levels;
        match self.features.haralick {
            HaralickSet::Paper => haralick(counts, l).to_array().to_vec(),
            HaralickSet::Full => {
                let weights: Vec<f64> = counts.iter().map(|&c| c as f64).collect();
                haralick_full(&weights, l).to_vec()
            }
        }
    }

    /// The quantisation and binning parameters.
    pub fn volume_params(&self) -> &VolumeParams {
        &self.volume
    }

    /// The co-occurrence parameters.
    pub fn glcm_params(&self) -> &GlcmParams {
        &self.glcm
    }
}

/// The error for GLCM offsets that pair no two cells: every one leaves the grid (or, in
/// 3D, the recording's `bins` time bins), so the co-occurrence matrix would be empty and
/// its features the same for every recording.
fn no_pairs(distances: &[usize], spikes: &SpikeTrains, kind: GlcmKind, bins: usize) -> ParamError {
    let shown: Vec<String> = distances.iter().map(ToString::to_string).collect();
    let at = match kind {
        GlcmKind::TwoD => format!(
            "{} on the {}x{} grid",
            shown.join(","),
            spikes.rows,
            spikes.cols
        ),
        GlcmKind::ThreeD => format!(
            "{} on the {}x{} grid over {bins} time bins",
            shown.join(","),
            spikes.rows,
            spikes.cols
        ),
    };
    let rule = "at least one distance must pair two cells: every offset at these distances leaves the grid (and the volume's time bins), so the co-occurrence matrix would be empty and its features the same for every recording; use distances shorter than the grid's longest side (or, in 3D, than its time bins)";
    ParamError::new("distances", rule, at)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::recording::Meta;
    use rand::seq::SliceRandom;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// Random sorted spike trains on a 3x3 grid whose centre cell holds no taxel.
    fn trains(rng: &mut ChaCha8Rng, present: &[bool], n_steps: usize) -> SpikeTrains {
        let lists: Vec<Vec<u32>> = present
            .iter()
            .map(|&p| {
                let rate = if p { rng.gen_range(0.0..0.08) } else { 0.0 };
                (0..n_steps as u32).filter(|_| rng.gen_bool(rate)).collect()
            })
            .collect();
        SpikeTrains::from_lists(&lists, 3, 3, present, n_steps)
    }

    /// E3's shortcut, the gray levels moved between cells, gives the row of the spike
    /// trains moved by `SpikeTrains::permuted` bit for bit, for one and two populations; a
    /// permutation that puts a taxel on the empty cell is refused.
    #[test]
    fn moved_gray_levels_give_the_row_of_the_moved_trains() {
        let present = [true, true, true, true, false, true, true, true, true];
        let taxels: Vec<usize> = (0..9).filter(|&c| present[c]).collect();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        for encoding in [Encoding::Sa, Encoding::SaFa] {
            let mut params = PipelineParams {
                encoding,
                ..PipelineParams::default()
            };
            params.volume.bin_ms = 50;
            let n_steps = 2_000;
            let sa = trains(&mut rng, &present, n_steps);
            let extractor = FeatureExtractor::new(&params, &sa.grid()).unwrap();
            let fa = (encoding == Encoding::SaFa).then(|| trains(&mut rng, &present, n_steps));
            let encoded = Encoded {
                meta: Meta::default(),
                spikes: sa,
                fa,
                resampled: false,
                flat: false,
                constant: false,
                from_events: false,
            };
            let levels = extractor.quantised_3d(&encoded).unwrap();
            for _ in 0..20 {
                let mut shuffled = taxels.clone();
                shuffled.shuffle(&mut rng);
                let mut perm: Vec<usize> = (0..9).collect();
                for (&from, &to) in taxels.iter().zip(&shuffled) {
                    perm[from] = to;
                }
                let moved = encoded.map_spikes(|s| s.permuted(&perm));
                let want = extractor.row(&moved, Method::Glcm3d).unwrap();
                let got = extractor.glcm3d_moved(&levels, &perm).unwrap();
                assert_eq!(
                    got.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    want.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    "{encoding:?} {perm:?}"
                );
            }
            let mut onto_empty: Vec<usize> = (0..9).collect();
            onto_empty.swap(0, 4);
            assert!(extractor.glcm3d_moved(&levels, &onto_empty).is_err());
        }
    }

    /// `rates` is each taxel's spike count over the slide's length in seconds, SA taxels
    /// then FA taxels, named by cell, with nothing for a cell without a taxel.
    #[test]
    fn rates_are_each_taxels_spikes_per_second() {
        let present = [true, true, true, true, false, true, true, true, true];
        let n_steps = 2_000;
        let lists = |base: u32| -> Vec<Vec<u32>> {
            (0..9u32)
                .map(|c| (0..c + base).map(|k| k * 7).collect())
                .collect()
        };
        let sa = SpikeTrains::from_lists(&lists(0), 3, 3, &present, n_steps);
        let fa = SpikeTrains::from_lists(&lists(10), 3, 3, &present, n_steps);
        let params = PipelineParams {
            encoding: Encoding::SaFa,
            ..PipelineParams::default()
        };
        let extractor = FeatureExtractor::new(&params, &sa.grid()).unwrap();
        let encoded = Encoded {
            meta: Meta::default(),
            spikes: sa,
            fa: Some(fa),
            resampled: false,
            flat: false,
            constant: false,
            from_events: false,
        };
        let row = extractor.row(&encoded, Method::Rates).unwrap();
        // 2 s of slide: cell c holds c spikes (SA) and c + 10 (FA); cell 4 has no taxel.
        let taxels = [0.0, 1.0, 2.0, 3.0, 5.0, 6.0, 7.0, 8.0];
        let want: Vec<f64> = taxels
            .iter()
            .map(|c| c / 2.0)
            .chain(taxels.iter().map(|c| (c + 10.0) / 2.0))
            .collect();
        assert_eq!(row, want);
        let names = extractor.names(Method::Rates);
        assert_eq!(names.len(), 16);
        assert_eq!(names[0], "sa_r0c0_msr");
        assert_eq!(names[15], "fa_r2c2_msr");
    }
}
