//! The pipeline's parameters: the feature method, the encoding, the Haralick set, and the
//! feature and pipeline parameters with their rules.

use serde::{Deserialize, Serialize};

use crate::encode::{FaParams, IzhikevichParams};
use crate::error::{ParamError, Result};
use crate::features::{GlcmParams, SpectrumParams, VolumeParams};
use crate::recording::Baseline;
use crate::signal::PreprocessParams;

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
    /// Every taxel's mean spike rate (MSR, spikes/s) in one vector: the spike counts a
    /// rate code keeps, without their timing. The spiking network reads the same spikes,
    /// so this method with logistic regression says how much their timing adds.
    #[serde(rename = "rates")]
    Rates,
}

impl Method {
    /// Every method, in the order of the enum.
    pub const ALL: [Method; 8] = [
        Method::Taxel,
        Method::Glcm2d,
        Method::Glcm3d,
        Method::AllTaxels,
        Method::AllTaxelsMm,
        Method::Glcm3dMulti,
        Method::Spectrum,
        Method::Rates,
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
            Method::Rates => "rates",
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
                    "method must be taxel, glcm2d, glcm3d, all-taxels, all-taxels-mm, glcm3d-multi, spectrum or rates",
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
    /// The stages' settings, one `name: value` line each, as results list them: the
    /// conditioning ([`PipelineParams::conditioning_lines`]), the encoder and encoding, the
    /// rate volume and GLCM, and the settings of the feature methods `methods`.
    pub fn describe(
        &self,
        layout: Option<Baseline>,
        slides: [usize; 2],
        methods: &[Method],
    ) -> Vec<String> {
        let mut lines = self.conditioning_lines(layout, slides);
        lines.push(self.encoder_line());
        lines.push(match self.encoding {
            Encoding::Sa => "encoding: sa".to_string(),
            other => format!("encoding: {other}; FA gain {}", self.fa.gain),
        });
        lines.push(self.volume_line());
        lines.extend(self.feature_lines(methods));
        lines
    }

    /// The conditioning as it applies to recordings of which `slides[0]` of `slides[1]`
    /// have their slide's times in the manifest: the low-pass, the phase kept, the baseline
    /// (the pipeline's own, else `layout`'s, the dataset's `layout.toml` choice) and the
    /// causal conditioning.
    pub fn conditioning_lines(
        &self,
        layout: Option<Baseline>,
        [with, all]: [usize; 2],
    ) -> Vec<String> {
        let pre = &self.preprocess;
        let low_pass = match pre.cutoff_hz > 0.0 {
            true => format!(
                "low-pass: {} Hz, zero-phase 2nd-order Butterworth",
                pre.cutoff_hz
            ),
            false => "low-pass: off".to_string(),
        };
        let phase = match (pre.slide_only, with) {
            (false, _) => "phase: the whole recording (--whole)".to_string(),
            (true, 0) => "phase: the whole recording (the manifest gives no slide times)".to_string(),
            (true, w) if w == all => "phase: the sliding phase, from the manifest's slide times".to_string(),
            (true, w) => format!("phase: the sliding phase in the {w} of {all} recordings whose slide times the manifest gives, the whole recording in the others"),
        };
        let baseline = match (pre.baseline, layout) {
            (Some(b), _) => format!("baseline: {b}"),
            (None, Some(b)) => format!("baseline: {b} (the dataset's layout.toml)"),
            (None, None) => "baseline: none".to_string(),
        };
        let mut lines = vec![low_pass, phase, baseline];
        if let Some(c) = &pre.causal {
            let drift = match pre.drift_window_ms {
                Some(ms) => format!("resting values tracked over {ms} ms"),
                None => "resting values fixed at training".to_string(),
            };
            lines.push(format!(
                "causal conditioning: forward-only low-pass, scale {} fixed at training, {drift}",
                c.scale
            ));
        }
        lines
    }

    /// The SA neurons and their gain.
    pub fn encoder_line(&self) -> String {
        let enc = &self.encoder;
        let overshoot = match enc.overshoot {
            crate::encode::Overshoot::Kept => "kept (Izhikevich's reference code)",
            crate::encode::Overshoot::Capped => "capped at the 30 mV peak",
        };
        // The firing type's name when a, b, c and d are one of Izhikevich's presets.
        let firing = crate::encode::FiringType::of(enc).map(|t| format!(" of type {t}"));
        format!(
            "encoder: Izhikevich (2003) neurons{}, a = {}, b = {}, c = {} mV, d = {}, overshoot \
             {overshoot}, gain G = {}",
            firing.unwrap_or_default(),
            enc.a,
            enc.b,
            enc.c,
            enc.d,
            enc.gain
        )
    }

    /// The rate volume and the GLCM's offsets.
    pub fn volume_line(&self) -> String {
        let (vol, glcm) = (&self.volume, &self.glcm);
        let symmetric = if glcm.symmetric {
            "symmetric"
        } else {
            "not symmetric"
        };
        format!(
            "rate volume: {} ms bins, {} gray levels; GLCM distances {:?}, 13 directions, {symmetric}",
            vol.bin_ms, vol.levels, glcm.distances
        )
    }

    /// The settings only some feature methods read, for those among `methods`.
    pub fn feature_lines(&self, methods: &[Method]) -> Vec<String> {
        let f = &self.features;
        let has = |m: Method| methods.contains(&m);
        let travel = match f.travel_mm > 0.0 {
            true => format!("the first {} mm of travel", f.travel_mm),
            false => "the whole phase".to_string(),
        };
        [
            (has(Method::Glcm2d) || has(Method::Glcm3d) || has(Method::Glcm3dMulti)).then(
                || match f.haralick {
                    HaralickSet::Paper => {
                        "Haralick features: contrast, correlation, ASM (the paper's)".to_string()
                    }
                    HaralickSet::Full => "Haralick features: the 13 of Haralick (1973)".to_string(),
                },
            ),
            has(Method::Glcm3dMulti)
                .then(|| format!("glcm3d-multi: bins of {:?} ms", f.bin_widths_ms)),
            has(Method::AllTaxelsMm)
                .then(|| format!("all-taxels-mm: Fano windows of {} mm", f.window_mm)),
            has(Method::Spectrum).then(|| {
                format!(
                    "spectrum: {} bins over {travel}, {} bands",
                    f.spectrum_bins, f.spectrum_bands
                )
            }),
        ]
        .into_iter()
        .flatten()
        .collect()
    }

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
