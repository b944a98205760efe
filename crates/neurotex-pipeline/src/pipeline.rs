//! The stages joined: a recording becomes spike trains, spike trains become a feature row.
//! Every stage is planned once (filter, GLCM offsets) and applied to many recordings,
//! in parallel across recordings.

use std::path::Path;

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::encode::{
    encode, encode_drives, encode_fa, encode_sa_fa, Drive, FaParams, IzhikevichParams, SpikeTrains,
};
use crate::error::{DataError, ParamError, Result};
use crate::events::Events;
use crate::features::glcm::GlcmKind;
use crate::features::{
    distance_stats, haralick, haralick_full, spike_stats, CountVolume, GlcmParams, GlcmPlan,
    Spectrum, SpectrumParams, VolumeParams, FULL_NAMES,
};
use crate::recording::{one_grid, Baseline, Dataset, Meta, Recording};
use crate::signal::{Conditioned, PreprocessParams, Preprocessor};
use crate::values::Grid;

/// The feature sets: the paper's three and the methods beyond the paper.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Method {
    /// MSR, CV_ISI and Fano factor of each taxel (approach 1), each taxel classified alone.
    #[serde(rename = "taxel")]
    Taxel,
    /// Contrast, correlation, ASM of the time-collapsed image's GLCM (the paper's control).
    #[serde(rename = "glcm2d")]
    Glcm2d,
    /// Contrast, correlation, ASM of the rate volume's mean 3D GLCM (approach 2).
    #[serde(rename = "glcm3d")]
    Glcm3d,
    /// Every taxel's MSR, CV_ISI and Fano factor in one vector, classified as one (the
    /// multi-taxel baseline the paper lacks); the columns of [`Method::Taxel`].
    #[serde(rename = "all-taxels")]
    AllTaxels,
    /// [`Method::AllTaxels`] in units of travelled distance (spikes per mm, Fano windows
    /// of fixed travel; [`crate::features::distance_stats`]), needing each recording's
    /// speed: a representation meant to be invariant to the sliding speed.
    #[serde(rename = "all-taxels-mm")]
    AllTaxelsMm,
    /// The 3D-GLCM features at each of [`FeatureParams::bin_widths_ms`], concatenated.
    #[serde(rename = "glcm3d-multi")]
    Glcm3dMulti,
    /// Each taxel's spike counts in equal bins of travel, their Fourier magnitudes in
    /// logarithmic bands of spatial frequency ([`crate::features::spectrum`]): the texture's
    /// spatial periods, whatever the speed, as Wang et al. (2022) read them from the signal.
    #[serde(rename = "spectrum")]
    Spectrum,
}

impl Method {
    /// Every method, in the order of the enum.
    pub const ALL: [Method; 7] = [
        Method::Taxel,
        Method::Glcm2d,
        Method::Glcm3d,
        Method::AllTaxels,
        Method::AllTaxelsMm,
        Method::Glcm3dMulti,
        Method::Spectrum,
    ];

    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Method::Taxel => "taxel",
            Method::Glcm2d => "glcm2d",
            Method::Glcm3d => "glcm3d",
            Method::AllTaxels => "all-taxels",
            Method::AllTaxelsMm => "all-taxels-mm",
            Method::Glcm3dMulti => "glcm3d-multi",
            Method::Spectrum => "spectrum",
        }
    }

    /// Whether the columns are three statistics per taxel, taxel by taxel.
    pub fn per_taxel(self) -> bool {
        matches!(
            self,
            Method::Taxel | Method::AllTaxels | Method::AllTaxelsMm
        )
    }
}

impl std::str::FromStr for Method {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, ParamError> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == s)
            .ok_or_else(|| {
                ParamError::new(
                    "method",
                    "method must be taxel, glcm2d, glcm3d, all-taxels, all-taxels-mm, glcm3d-multi or spectrum",
                    s,
                )
            })
    }
}

/// Which mechanoreceptor populations encode the signal.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
pub enum Encoding {
    /// Slowly adapting (SA-I) neurons driven by the signal, the paper's.
    #[default]
    #[serde(rename = "sa")]
    Sa,
    /// Fast-adapting (FA-I) neurons driven by its rectified rate of change
    /// ([`crate::encode::FaParams`]).
    #[serde(rename = "fa")]
    Fa,
    /// Both populations, each with its own features (SA columns, then FA columns).
    #[serde(rename = "sa+fa")]
    SaFa,
}

impl Encoding {
    /// The command-line name.
    pub fn name(self) -> &'static str {
        match self {
            Encoding::Sa => "sa",
            Encoding::Fa => "fa",
            Encoding::SaFa => "sa+fa",
        }
    }

    /// The column-name prefix of each population, in the order of
    /// [`Encoded::populations`]: empty for a single population.
    pub fn prefixes(self) -> &'static [&'static str] {
        match self {
            Encoding::Sa | Encoding::Fa => &[""],
            Encoding::SaFa => &["sa_", "fa_"],
        }
    }
}

impl std::fmt::Display for Encoding {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for Encoding {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, ParamError> {
        [Encoding::Sa, Encoding::Fa, Encoding::SaFa]
            .into_iter()
            .find(|e| e.name() == s)
            .ok_or_else(|| ParamError::new("encoding", "encoding must be sa, fa or sa+fa", s))
    }
}

/// Which Haralick features the GLCM methods compute.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum HaralickSet {
    /// Contrast, correlation and ASM (the paper's eqs. 5-8).
    #[default]
    Paper,
    /// The 13 features of [`crate::features::haralick_full`].
    Full,
}

impl std::fmt::Display for HaralickSet {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            HaralickSet::Paper => "paper",
            HaralickSet::Full => "full",
        })
    }
}

impl std::str::FromStr for HaralickSet {
    type Err = ParamError;
    fn from_str(s: &str) -> Result<Self, ParamError> {
        match s {
            "paper" => Ok(HaralickSet::Paper),
            "full" => Ok(HaralickSet::Full),
            _ => Err(ParamError::new(
                "haralick",
                "haralick must be paper or full",
                s,
            )),
        }
    }
}

/// Parameters of the feature methods beyond the paper's.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct FeatureParams {
    /// The Haralick features of the GLCM methods.
    pub haralick: HaralickSet,
    /// The rate-volume bin widths of [`Method::Glcm3dMulti`], in ms.
    pub bin_widths_ms: Vec<usize>,
    /// The Fano window of [`Method::AllTaxelsMm`] in mm of travel (2 mm: the paper's
    /// 200 ms window at 10 mm/s).
    pub window_mm: f64,
    /// The equal bins [`Method::Spectrum`] counts spikes in (128: at FabricSlide's 590 mm
    /// slides about 4.6 mm each, near its samples' spacing at 150 mm/s; on the simulated
    /// rig's 90 mm, 0.7 mm).
    pub spectrum_bins: usize,
    /// The logarithmic bands of [`Method::Spectrum`] (16, 14 after merging at 128 bins).
    pub spectrum_bands: usize,
    /// The span of [`Method::Spectrum`] in mm of travel from the start of the selected
    /// phase; 0 (the default) for each recording's whole phase.
    pub travel_mm: f64,
}

impl Default for FeatureParams {
    fn default() -> Self {
        FeatureParams {
            haralick: HaralickSet::Paper,
            bin_widths_ms: vec![50, 100, 200, 400],
            window_mm: 2.0,
            spectrum_bins: 128,
            spectrum_bands: 16,
            travel_mm: 0.0,
        }
    }
}

impl FeatureParams {
    /// Checks the rules: at least one bin width, each at least 1 ms; a positive window.
    ///
    /// # Errors
    /// The rule broken.
    pub fn check(&self) -> Result<(), ParamError> {
        if self.bin_widths_ms.is_empty() || self.bin_widths_ms.contains(&0) {
            return Err(ParamError::new(
                "bin-widths",
                "bin widths must be at least one width, each at least 1 ms",
                format!("{:?}", self.bin_widths_ms),
            ));
        }
        if !(self.window_mm.is_finite() && self.window_mm > 0.0) {
            return Err(ParamError::new(
                "window-mm",
                "the travelled-distance window must be a positive number of mm",
                self.window_mm,
            ));
        }
        if !(8..=crate::features::spectrum::MAX_BINS).contains(&self.spectrum_bins) {
            return Err(ParamError::new(
                "spectrum-bins",
                "the spectrum's bins must be 8 to 4096",
                self.spectrum_bins,
            ));
        }
        if self.spectrum_bands == 0 {
            let rule = "the spectrum needs at least one band";
            return Err(ParamError::new("spectrum-bands", rule, 0));
        }
        if !(self.travel_mm.is_finite() && self.travel_mm >= 0.0) {
            return Err(ParamError::new(
                "travel-mm",
                "the spectrum's travel must be 0 (the whole slide) or a positive number of mm",
                self.travel_mm,
            ));
        }
        Ok(())
    }

    /// The spectrum's bins and bands.
    pub fn spectrum(&self) -> SpectrumParams {
        SpectrumParams {
            bins: self.spectrum_bins,
            bands: self.spectrum_bands,
        }
    }
}

/// All stage parameters, each with the paper's value as default (or, where the paper gives
/// none, a choice whose reasons docs/decisions/ gives). The fields after `glcm` default
/// when absent, so model files written before them load with the paper's SA encoding.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
pub struct PipelineParams {
    /// Conditioning.
    pub preprocess: PreprocessParams,
    /// Neuron model and gain (of the SA population; the FA population uses its firing type).
    pub encoder: IzhikevichParams,
    /// Rate volume bins (also the Fano window) and quantisation.
    pub volume: VolumeParams,
    /// Co-occurrence offsets.
    pub glcm: GlcmParams,
    /// The populations that encode.
    #[serde(default)]
    pub encoding: Encoding,
    /// The FA population's gain.
    #[serde(default)]
    pub fa: FaParams,
    /// Multi-scale widths, Haralick set and travelled-distance window.
    #[serde(default)]
    pub features: FeatureParams,
}

impl PipelineParams {
    /// Checks every stage's rules.
    ///
    /// # Errors
    /// The first rule broken.
    pub fn check(&self) -> Result<(), ParamError> {
        self.preprocess.check()?;
        self.encoder.check()?;
        self.volume.check()?;
        self.glcm.check()?;
        self.fa.check()?;
        self.features.check()
    }
}

/// The taxel grid every encoded recording shares (size and mask).
///
/// # Errors
/// Recordings on different grids, the first that differs named; no recording.
pub fn shared_grid(encoded: &[Encoded]) -> Result<Grid> {
    let grids = encoded
        .iter()
        .map(|e| {
            let s = &e.spikes;
            Ok((
                e.meta.file.as_str(),
                Grid::masked(s.rows, s.cols, s.present.clone())?,
            ))
        })
        .collect::<Result<Vec<_>>>()?;
    one_grid(grids)
}

/// One recording's spikes with what the conditioning noticed.
#[derive(Debug, Clone, PartialEq)]
pub struct Encoded {
    /// The recording's manifest fields.
    pub meta: Meta,
    /// The first population's spike trains over the selected phase: SA for the `sa` and
    /// `sa+fa` encodings, FA for `fa`.
    pub spikes: SpikeTrains,
    /// The FA population of an `sa+fa` encoding; `None` for a single population.
    pub fa: Option<SpikeTrains>,
    /// The input was resampled to 1 kHz.
    pub resampled: bool,
    /// The recording had no positive signal and was left at zero.
    pub flat: bool,
    /// The spikes are a sensor's address events, not the encoder's.
    pub from_events: bool,
}

impl Encoded {
    /// The populations in feature order: `spikes`, then `fa` when present.
    pub fn populations(&self) -> impl Iterator<Item = &SpikeTrains> {
        std::iter::once(&self.spikes).chain(self.fa.as_ref())
    }

    /// The same recording with every population transformed by `f` (truncation,
    /// permutation).
    pub fn map_spikes(&self, f: impl Fn(&SpikeTrains) -> SpikeTrains) -> Encoded {
        Encoded {
            spikes: f(&self.spikes),
            fa: self.fa.as_ref().map(&f),
            ..self.clone()
        }
    }
}

/// The planned pipeline.
#[derive(Debug, Clone)]
pub struct Pipeline {
    params: PipelineParams,
    preprocessor: Preprocessor,
}

impl Pipeline {
    /// Checks the parameters and plans the stages.
    ///
    /// # Errors
    /// A broken parameter rule.
    pub fn new(params: PipelineParams) -> Result<Self, ParamError> {
        params.check()?;
        let preprocessor = Preprocessor::new(&params.preprocess)?;
        Ok(Pipeline {
            params,
            preprocessor,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &PipelineParams {
        &self.params
    }

    /// Conditions one recording (sliding phase, 1 kHz, baseline, low-pass, normalised),
    /// checking it lasts at least one bin.
    ///
    /// # Errors
    /// An empty sliding phase or a selected phase shorter than one bin.
    pub fn condition(&self, rec: &Recording, dataset_baseline: Baseline) -> Result<Conditioned> {
        let cond = self.preprocessor.apply(rec, dataset_baseline)?;
        let bin = self.params.volume.bin_ms;
        if cond.n_steps() < bin {
            return Err(DataError::invalid(
                &rec.meta.file,
                format!(
                    "the selected phase lasts {} ms, shorter than one {bin} ms bin",
                    cond.n_steps()
                ),
            )
            .into());
        }
        Ok(cond)
    }

    /// Encodes a conditioned recording with the pipeline's SA neurons.
    ///
    /// # Errors
    /// A broken encoder rule.
    pub fn encode_conditioned(&self, rec: &Recording, cond: &Conditioned) -> Result<SpikeTrains> {
        let l = &rec.layout;
        let params = self.params.encoder;
        Ok(encode(&cond.samples, l.rows, l.cols, &l.present, params)?)
    }

    /// Encodes a conditioned recording with the populations of the pipeline's encoding:
    /// `(first population, FA population of sa+fa)`, as [`Encoded::spikes`] and
    /// [`Encoded::fa`].
    ///
    /// # Errors
    /// A broken encoder rule.
    pub fn encode_populations(
        &self,
        rec: &Recording,
        cond: &Conditioned,
    ) -> Result<(SpikeTrains, Option<SpikeTrains>)> {
        let l = &rec.layout;
        let fa = || {
            encode_fa(
                &cond.samples,
                l.rows,
                l.cols,
                &l.present,
                self.params.encoder,
                self.params.fa,
            )
        };
        Ok(match self.params.encoding {
            Encoding::Sa => (self.encode_conditioned(rec, cond)?, None),
            Encoding::Fa => (fa()?, None),
            Encoding::SaFa => {
                let (sa, fa) = self.encode_sa_fa(rec, cond)?;
                (sa, Some(fa))
            }
        })
    }

    /// Encodes several inputs of one recording (conditioned signals of its grid and of one
    /// length, such as the perturbed draws of the encoder's sensitivity) with the
    /// populations of the pipeline's encoding, all in one call: the same trains, bit for
    /// bit, as [`Pipeline::encode_populations`] of each input alone, in the order of
    /// `inputs`.
    ///
    /// Each population of each input is a bank of neurons of its own, and the banks run
    /// side by side ([`encode_drives`]): a neuron's state depends on its own input only, so
    /// the vector lanes hold several inputs' neurons at once without changing a bit.
    ///
    /// # Errors
    /// A broken encoder rule.
    ///
    /// # Panics
    /// If the inputs differ in length (a caller bug).
    pub fn encode_populations_side_by_side(
        &self,
        rec: &Recording,
        inputs: &[&[f64]],
    ) -> Result<Vec<(SpikeTrains, Option<SpikeTrains>)>> {
        let (l, p) = (&rec.layout, &self.params);
        let encoding = p.encoding;
        if encoding != Encoding::Sa {
            p.fa.check()?;
        }
        let mut drives = Vec::new();
        let mut gains = Vec::new();
        for &input in inputs {
            if encoding != Encoding::Fa {
                drives.push(Drive::Signal(input));
                gains.push(p.encoder.gain);
            }
            if encoding != Encoding::Sa {
                drives.push(Drive::RectifiedRate(input));
                gains.push(p.fa.gain);
            }
        }
        // FA alone runs the SA firing type at the FA gain, as `encode_fa` does.
        let neuron = match encoding {
            Encoding::Fa => p.encoder.with_gain(p.fa.gain),
            Encoding::Sa | Encoding::SaFa => p.encoder,
        };
        let trains = encode_drives(&mut drives, &gains, l.rows, l.cols, &l.present, neuron)?;
        let mut trains = trains.into_iter();
        let mut next = || trains.next().expect("one bank per population and input");
        Ok(inputs
            .iter()
            .map(|_| match encoding {
                Encoding::Sa | Encoding::Fa => (next(), None),
                Encoding::SaFa => (next(), Some(next())),
            })
            .collect())
    }

    /// Encodes a conditioned recording with the pipeline's SA neurons and its FA
    /// population side by side ([`encode_sa_fa`]), whatever the pipeline's encoding.
    ///
    /// # Errors
    /// A broken encoder rule.
    pub fn encode_sa_fa(
        &self,
        rec: &Recording,
        cond: &Conditioned,
    ) -> Result<(SpikeTrains, SpikeTrains)> {
        let (l, p) = (&rec.layout, &self.params);
        Ok(encode_sa_fa(
            &cond.samples,
            l.rows,
            l.cols,
            &l.present,
            p.encoder,
            p.fa,
        )?)
    }

    /// Conditions and encodes one recording.
    ///
    /// # Errors
    /// An empty sliding phase or a selected phase shorter than one bin.
    pub fn encode(&self, rec: &Recording, dataset_baseline: Baseline) -> Result<Encoded> {
        let cond = self.condition(rec, dataset_baseline)?;
        self.encode_recording(rec, &cond)
    }

    /// Encodes a conditioned recording with the populations of the pipeline's encoding.
    ///
    /// # Errors
    /// A broken encoder rule.
    fn encode_recording(&self, rec: &Recording, cond: &Conditioned) -> Result<Encoded> {
        let (spikes, fa) = self.encode_populations(rec, cond)?;
        Ok(Encoded {
            meta: rec.meta.clone(),
            spikes,
            fa,
            resampled: cond.resampled,
            flat: cond.flat,
            from_events: false,
        })
    }

    /// Loads and encodes the dataset's recordings `indices` in parallel, calling
    /// `on_done` once per finished recording (for a progress bar). The output keeps the
    /// order of `indices`; a dataset's raw samples are never all in memory at once.
    ///
    /// # Errors
    /// The first failing recording's error.
    pub fn encode_dataset(
        &self,
        dataset: &Dataset,
        indices: &[usize],
        on_done: &(dyn Fn() + Sync),
    ) -> Result<Vec<Encoded>> {
        if dataset.is_events() {
            return indices
                .par_iter()
                .map(|&i| {
                    let events = dataset.load_events(i)?;
                    let path = dataset.root.join(&dataset.entries[i].file);
                    let encoded = self.from_events(dataset.entries[i].clone(), events, &path)?;
                    on_done();
                    Ok(encoded)
                })
                .collect();
        }
        let pairs = self.encode_dataset_with(dataset, indices, on_done, &|_, _| Ok(()))?;
        Ok(pairs.into_iter().map(|(e, ())| e).collect())
    }

    /// An address-event recording as the pipeline's encoding reads it: its ON trains in
    /// the SA population's place and its OFF trains in the FA population's (`sa` reads ON,
    /// `fa` OFF, `sa+fa` both). The encoder does not run.
    ///
    /// # Errors
    /// `fa` or `sa+fa` on a recording without polarities.
    pub fn from_events(&self, meta: Meta, events: Events, path: &Path) -> Result<Encoded> {
        events_encoded(self.params.encoding, meta, events, path)
    }
    /// [`Pipeline::encode_dataset`], also applying `also` to each recording and its
    /// conditioned signal while both are in memory (the baselines without spikes read
    /// the signal the encoder receives without conditioning it twice).
    ///
    /// # Errors
    /// The first failing recording's error, from the encoding or from `also`.
    pub fn encode_dataset_with<T: Send>(
        &self,
        dataset: &Dataset,
        indices: &[usize],
        on_done: &(dyn Fn() + Sync),
        also: &(dyn Fn(&Recording, &Conditioned) -> Result<T> + Sync),
    ) -> Result<Vec<(Encoded, T)>> {
        let baseline = dataset.layout.baseline.unwrap_or_default();
        indices
            .par_iter()
            .map(|&i| {
                let rec = dataset.load(i)?;
                let cond = self.condition(&rec, baseline)?;
                let encoded = self.encode_recording(&rec, &cond)?;
                let extra = also(&rec, &cond)?;
                on_done();
                Ok((encoded, extra))
            })
            .collect()
    }

    /// A feature extractor for trains of this grid.
    ///
    /// # Errors
    /// A broken parameter rule.
    pub fn extractor(&self, grid: &Grid) -> Result<FeatureExtractor, ParamError> {
        FeatureExtractor::new(&self.params, grid)
    }
}

/// [`Pipeline::from_events`] for `encoding`.
///
/// # Errors
/// `fa` or `sa+fa` on a recording without polarities.
pub fn events_encoded(
    encoding: Encoding,
    meta: Meta,
    events: Events,
    path: &Path,
) -> Result<Encoded> {
    let trains = |lists: &[Vec<u32>]| {
        SpikeTrains::from_lists(
            lists,
            events.rows,
            events.cols,
            &events.present,
            events.n_steps,
        )
    };
    let off = || {
        events.off.as_deref().map(trains).ok_or_else(|| {
                let why = format!(
                    "has no polarity column, so no OFF events: the `{}` encoding reads OFF events as its FA population; use --encoding sa (ON events)",
                    encoding.name()
                );
                crate::Error::from(DataError::invalid(path, why))
            })
    };
    let (spikes, fa) = match encoding {
        Encoding::Sa => (trains(&events.on), None),
        Encoding::Fa => (off()?, None),
        Encoding::SaFa => (trains(&events.on), Some(off()?)),
    };
    Ok(Encoded {
        meta,
        spikes,
        fa,
        resampled: false,
        flat: false,
        from_events: true,
    })
}

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
        let per_taxel = |stats: [&str; 3]| -> Vec<String> {
            self.grid
                .taxels()
                .flat_map(|cell| {
                    let cell = self.grid.cell(cell);
                    stats.map(|f| format!("{cell}_{f}"))
                })
                .collect()
        };
        match method {
            Method::Taxel | Method::AllTaxels => per_taxel(["msr", "cv_isi", "fano"]),
            Method::AllTaxelsMm => per_taxel(["spikes_per_mm", "cv_isi", "fano_mm"]),
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

/// Why [`Method::AllTaxelsMm`] refuses a recording without a speed.
const NO_SPEED: &str =
    "the all-taxels-mm method needs the recording's sliding speed (manifest column speed_mm_s, nonzero)";

/// One population's [`Method::Spectrum`] column names on `grid`: `{cell}_f{lo}_{hi}` for
/// each taxel's band of frequencies `lo` to `hi - 1` cycles over the span.
pub fn spectrum_names(grid: &Grid, features: &FeatureParams) -> Vec<String> {
    let edges = features.spectrum().edges();
    grid.taxels()
        .flat_map(|cell| {
            let cell = grid.cell(cell);
            edges
                .windows(2)
                .map(move |w| format!("{cell}_f{}_{}", w[0], w[1]))
        })
        .collect()
}

/// The steps [`Method::Spectrum`] reads of a phase of `n_steps` at `speed_mm_s`: all of
/// them, or those of `travel_mm` of travel.
///
/// # Errors
/// Why the recording cannot give that span: no speed, or a slide shorter than the travel
/// or than one step per bin.
pub fn spectrum_span(
    n_steps: usize,
    speed_mm_s: Option<f64>,
    features: &FeatureParams,
) -> std::result::Result<usize, String> {
    let span = if features.travel_mm > 0.0 {
        let Some(speed) = speed_mm_s.filter(|s| s.is_finite() && *s != 0.0) else {
            return Err("the spectrum's --travel-mm needs the recording's sliding speed (manifest column speed_mm_s, nonzero); --travel-mm 0 uses the whole slide without it".into());
        };
        let steps = (features.travel_mm / speed.abs() * 1e3).round() as usize;
        // A slide's stamps span one sample less than its travel: up to 1 % short reads whole.
        if steps > n_steps + n_steps / 100 {
            return Err(format!(
                "its slide travels {:.2} mm ({n_steps} ms at {} mm/s), less than the spectrum's travel (--travel-mm {})",
                n_steps as f64 * 1e-3 * speed.abs(),
                speed.abs(),
                features.travel_mm
            ));
        }
        steps.min(n_steps)
    } else {
        n_steps
    };
    if span < features.spectrum_bins {
        return Err(format!(
            "the spectrum's span is {span} ms, fewer than its {} bins (--spectrum-bins)",
            features.spectrum_bins
        ));
    }
    Ok(span)
}

/// The error of trains shorter than one bin of `bin_ms`.
fn too_short(spikes: &SpikeTrains, bin_ms: usize) -> crate::Error {
    DataError::TooShort {
        n_ms: spikes.n_steps,
        bin_ms,
    }
    .into()
}

/// Row-major indices of the cells holding a taxel.
pub fn taxel_cells(present: &[bool]) -> impl Iterator<Item = usize> + '_ {
    present
        .iter()
        .enumerate()
        .filter(|(_, &p)| p)
        .map(|(i, _)| i)
}

#[cfg(test)]
mod tests {
    use super::*;
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
}
