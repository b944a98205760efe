//! The stage options, defined once: each option's name, help, kind and default, how its
//! text is parsed into [`StageOptions`], and the check that turns the options into the
//! pipeline's validated parameters ([`StageOptions::check`]). The CLI builds its flags
//! from [`STAGE_OPTIONS`] (`bin_ms` is `--bin-ms`), the Python package its keyword
//! arguments and their defaults (`bin_ms=200`), so a default or a rule is written here only.
//! The classifiers' knobs are defined in the same way in [`classifiers`].

use crate::calibrate::GainChoice;
use crate::encode::{FaParams, FiringType, Overshoot};
use crate::features::{GlcmParams, VolumeParams};
use crate::pipeline::{Encoding, FeatureParams, HaralickSet, PipelineParams};
use crate::recording::Baseline;
use crate::signal::PreprocessParams;
use crate::values::ParamError;

pub mod classifiers;

pub use classifiers::{classifier_with, knobs_of, snn_with, KnobSpec, CLASSIFIER_OPTIONS};

/// What kind of value an option takes, for the front ends' parsers and types.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum OptionKind {
    /// A real number (`2.5`).
    Number,
    /// A count (`200`).
    Count,
    /// Counts separated by commas (`1,2`); a list in Python.
    Counts,
    /// On or off: a flag on the command line, a `bool` in Python.
    Flag,
    /// `true` or `false` given as a value (`--bootstrap false`), for a switch that is on
    /// by default; a `bool` in Python.
    Bool,
    /// A name from a fixed set, or (the gain) a number or a name.
    Text,
}

/// One stage option.
pub struct OptionSpec {
    /// Its name as Python spells it; the command line's flag is this with `-` for `_`.
    pub name: &'static str,
    /// What it does, with its paper value or reason.
    pub help: &'static str,
    /// The kind of value it takes.
    pub kind: OptionKind,
    /// Its value in `options` as text, as it is typed; `None` for an option without a
    /// value (a baseline taken from the dataset's layout).
    pub get: fn(&StageOptions) -> Option<String>,
    /// Sets it in `options` from text as it is typed; the error says what was expected.
    pub set: fn(&mut StageOptions, &str) -> Result<(), String>,
}

impl OptionSpec {
    /// The command line's spelling: `--bin-ms` for `bin_ms`, without the dashes.
    pub fn flag(&self) -> String {
        self.name.replace('_', "-")
    }

    /// Its default as text ([`StageOptions::default`]), `None` when it has none.
    pub fn default_text(&self) -> Option<String> {
        (self.get)(&StageOptions::default())
    }
}

impl std::fmt::Debug for OptionSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("OptionSpec")
            .field("name", &self.name)
            .field("kind", &self.kind)
            .finish()
    }
}

/// The stage options as chosen, before they are checked: every stage's parameter a user
/// sets, plus what is calibrated on training recordings before the pipeline runs.
#[derive(Debug, Clone, PartialEq)]
pub struct StageOptions {
    /// The encoder's gain, or `auto` with its target rate.
    pub gain: GainChoice,
    /// Condition causally, as a live stream can.
    pub causal: bool,
    /// Under `causal`, the trailing window (s) over which each taxel's resting value is
    /// tracked as its least input; 0 keeps the resting values fixed at training.
    pub drift_window_s: f64,
    /// The Izhikevich firing type.
    pub preset: FiringType,
    /// The membrane value the neurons' recovery reads at a spike's step.
    pub overshoot: Overshoot,
    /// Low-pass cutoff in Hz; 0 turns the filter off.
    pub cutoff: f64,
    /// Baseline removal; `None` takes the dataset's layout's.
    pub baseline: Option<Baseline>,
    /// The whole recording instead of its sliding phase.
    pub whole: bool,
    /// Gray levels for GLCM quantisation.
    pub levels: usize,
    /// Rate-volume bin and Fano window in ms.
    pub bin_ms: usize,
    /// GLCM offset distances.
    pub distances: Vec<usize>,
    /// Co-occurrences counted both ways.
    pub symmetric: bool,
    /// Mechanoreceptor populations.
    pub encoding: Encoding,
    /// Gain of the FA neurons.
    pub fa_gain: f64,
    /// Haralick features of the GLCM methods.
    pub haralick: HaralickSet,
    /// Rate-volume bin widths of `glcm3d-multi`, in ms.
    pub bin_widths: Vec<usize>,
    /// Fano window of `all-taxels-mm`, in mm of travel.
    pub window_mm: f64,
    /// Bins of the `spectrum` method's span.
    pub spectrum_bins: usize,
    /// Logarithmic bands of the `spectrum` method.
    pub spectrum_bands: usize,
    /// The `spectrum` method's span in mm of travel; 0 for the whole selected phase.
    pub travel_mm: f64,
}

impl Default for StageOptions {
    /// The library's defaults: the paper's values, or where it gives none a choice whose
    /// reasons docs/decisions/ gives.
    fn default() -> Self {
        let (pre, volume) = (PreprocessParams::default(), VolumeParams::default());
        let features = FeatureParams::default();
        Self {
            gain: GainChoice::default(),
            causal: false,
            drift_window_s: 0.0,
            preset: FiringType::default(),
            overshoot: Overshoot::default(),
            cutoff: pre.cutoff_hz,
            baseline: pre.baseline,
            whole: !pre.slide_only,
            levels: volume.levels,
            bin_ms: volume.bin_ms,
            distances: GlcmParams::default().distances,
            symmetric: GlcmParams::default().symmetric,
            encoding: Encoding::default(),
            fa_gain: FaParams::default().gain,
            haralick: features.haralick,
            bin_widths: features.bin_widths_ms,
            window_mm: features.window_mm,
            spectrum_bins: features.spectrum_bins,
            spectrum_bands: features.spectrum_bands,
            travel_mm: features.travel_mm,
        }
    }
}

/// The stage options checked: the pipeline's parameters and what is still to be
/// calibrated on the training recordings before they apply. The parameters are reached
/// in one of two ways, so that none is used with a gain or a conditioning that is still
/// to be chosen: [`CheckedStages::fixed`] when nothing is left to calibrate, and
/// [`CheckedStages::calibrate`] (or, for an analysis that calibrates inside its own
/// loops, [`CheckedStages::to_calibrate`]).
#[derive(Debug, Clone, PartialEq)]
pub struct CheckedStages {
    /// The pipeline parameters, checked; under `auto` gain the encoder's gain is the
    /// firing type's until calibration chooses it, and under `causal` the conditioning
    /// has no resting values yet.
    params: PipelineParams,
    /// The gain as chosen: a number, or `auto` with its target rate.
    pub gain: GainChoice,
    /// Causal conditioning: resting values and a scale fixed on training recordings.
    pub causal: bool,
}

impl CheckedStages {
    /// The target rate of an `auto` gain, or `None` for a gain given as a number.
    pub fn gain_target(&self) -> Option<f64> {
        self.gain.target_hz()
    }

    /// The pipeline's parameters when nothing is left to calibrate (a gain given as a
    /// number, conditioning recording by recording); `None` under `auto` gain or `causal`.
    pub fn fixed(&self) -> Option<&PipelineParams> {
        (self.gain_target().is_none() && !self.causal).then_some(&self.params)
    }

    /// The parameters before calibration, for a caller that calibrates them itself (each
    /// analysis's training set its own gain, or one recording's): under `auto` gain the
    /// encoder's gain is the firing type's until then.
    pub fn to_calibrate(&self) -> &PipelineParams {
        &self.params
    }

    /// The parameters with the gain and the causal conditioning chosen on the recordings
    /// `indices` (loaded by `load`; labels are not read).
    ///
    /// # Errors
    /// As [`crate::calibrate::calibrate_pipeline`].
    pub fn calibrate(
        &self,
        load: &(dyn Fn(usize) -> crate::error::Result<crate::recording::Recording> + Sync),
        indices: &[usize],
        baseline: Baseline,
    ) -> crate::error::Result<crate::calibrate::CalibratedParams> {
        let params = self.params.clone();
        crate::calibrate::calibrate_pipeline(
            params,
            self.causal,
            self.gain,
            load,
            indices,
            baseline,
        )
    }
}

impl StageOptions {
    /// The pipeline parameters these options name, checked once; stages take only this
    /// checked form.
    ///
    /// # Errors
    /// A parameter outside its range, named as the command line spells it.
    pub fn check(&self) -> Result<CheckedStages, ParamError> {
        let gain = match self.gain {
            GainChoice::Fixed(g) => g,
            GainChoice::Auto { .. } => crate::encode::IzhikevichParams::default().gain,
        };
        let mut p = PipelineParams {
            encoder: self
                .preset
                .params()
                .with_gain(gain)
                .with_overshoot(self.overshoot),
            ..PipelineParams::default()
        };
        p.preprocess.cutoff_hz = self.cutoff;
        p.preprocess.slide_only = !self.whole;
        p.preprocess.baseline = self.baseline;
        p.preprocess.drift_window_ms = self.drift_window_ms()?;
        p.volume.levels = self.levels;
        p.volume.bin_ms = self.bin_ms;
        p.glcm.distances = self.distances.clone();
        p.glcm.symmetric = self.symmetric;
        p.encoding = self.encoding;
        p.fa.gain = self.fa_gain;
        p.features = FeatureParams {
            haralick: self.haralick,
            bin_widths_ms: self.bin_widths.clone(),
            window_mm: self.window_mm,
            spectrum_bins: self.spectrum_bins,
            spectrum_bands: self.spectrum_bands,
            travel_mm: self.travel_mm,
        };
        p.check()?;
        Ok(CheckedStages {
            params: p,
            gain: self.gain,
            causal: self.causal,
        })
    }

    /// The drift window in ms; `None` for 0.
    ///
    /// # Errors
    /// A window without causal conditioning (it would go unused), or one that is not a
    /// whole number of 0.1 s from 0.1 to 600 s.
    fn drift_window_ms(&self) -> Result<Option<u32>, ParamError> {
        let s = self.drift_window_s;
        if s == 0.0 {
            return Ok(None);
        }
        let rule = "the drift window must be a multiple of 0.1 s from 0.1 to 600 s";
        let tenths = s * 10.0;
        if !(tenths.is_finite()
            && (tenths - tenths.round()).abs() < 1e-9
            && (1.0..=6000.0).contains(&tenths.round()))
        {
            return Err(ParamError::new("drift-window-s", rule, s));
        }
        if !self.causal {
            let rule = "the drift window tracks the resting values of causal conditioning: it needs --causal";
            return Err(ParamError::new("drift-window-s", rule, s));
        }
        Ok(Some(tenths.round() as u32 * 100))
    }

    /// Sets the option `name` (Python's spelling) from text as it is typed.
    ///
    /// # Errors
    /// No such option, or a value it does not take; the message names the options.
    pub fn set(&mut self, name: &str, text: &str) -> Result<(), String> {
        let spec = option(name).ok_or_else(|| {
            let names: Vec<&str> = STAGE_OPTIONS.iter().map(|o| o.name).collect();
            format!(
                "unknown option `{name}`; the options are {}",
                names.join(", ")
            )
        })?;
        (spec.set)(self, text)
    }
}

/// The stage option called `name` (Python's spelling).
pub fn option(name: &str) -> Option<&'static OptionSpec> {
    STAGE_OPTIONS.iter().find(|o| o.name == name)
}

/// Parses a value with its type's `FromStr`, the error as text naming the value.
fn parse<T: std::str::FromStr>(text: &str) -> Result<T, String>
where
    T::Err: std::fmt::Display,
{
    text.trim().parse().map_err(|e: T::Err| {
        // A number's error ("invalid digit found in string") does not show the value.
        let e = crate::error::number_words(&e.to_string());
        match e.contains(text.trim()) {
            true => e,
            false => format!("`{text}`: {e}"),
        }
    })
}

/// Parses a name from a fixed set with its type's `FromStr`; the error is the rule and the
/// value (the front end names the option).
fn choice<T: std::str::FromStr<Err = ParamError>>(text: &str) -> Result<T, String> {
    text.trim()
        .parse()
        .map_err(|e: ParamError| format!("{}, got {}", e.rule, e.got))
}

/// `on` or `off` as a flag's text: `true`/`false`.
fn flag(text: &str) -> Result<bool, String> {
    match text.trim() {
        "true" => Ok(true),
        "false" => Ok(false),
        t => Err(format!("expected true or false, got `{t}`")),
    }
}

/// A value as it is typed.
fn shown<T: std::fmt::Display>(value: &T) -> Option<String> {
    Some(value.to_string())
}

/// Counts separated by commas; none for empty text (the stage's check names its rule).
fn counts(text: &str) -> Result<Vec<usize>, String> {
    if text.trim().is_empty() {
        return Ok(Vec::new());
    }
    text.split(',').map(parse::<usize>).collect()
}

/// Counts as they are typed: `1,2`.
fn join(values: &[usize]) -> String {
    values
        .iter()
        .map(usize::to_string)
        .collect::<Vec<_>>()
        .join(",")
}

/// The spec of a field: its name, help, kind, and how to read and write it as text.
macro_rules! spec {
    ($name:ident, $kind:ident, $help:expr, get: $get:expr, set: $set:expr) => {
        OptionSpec {
            name: stringify!($name),
            help: $help,
            kind: OptionKind::$kind,
            get: |o: &StageOptions| ($get)(&o.$name),
            set: |o: &mut StageOptions, t: &str| {
                o.$name = ($set)(t)?;
                Ok(())
            },
        }
    };
    ($name:ident, $kind:ident, $help:expr) => {
        spec!($name, $kind, $help,
            get: shown, set: parse)
    };
}

/// Every stage option, in the order `--help` lists them.
pub static STAGE_OPTIONS: &[OptionSpec] = &[
    spec!(
        gain,
        Text,
        "Gain G from normalised signal to Izhikevich input current (paper: 8). `auto` chooses \
         it on the training recordings (labels unused) so that the median taxel with any \
         signal fires at 20 Hz during the slide; `auto:HZ` sets another target rate."
    ),
    spec!(
        preset,
        Text,
        "Izhikevich firing type: RS (slowly adapting, the paper's), IB, CH, FS, LTS, TC, RZ.",
        get: shown,
        set: choice
    ),
    spec!(
        overshoot,
        Text,
        "The membrane value the neurons' recovery reads at the step they cross the 30 mV \
         peak: `kept` (Izhikevich's reference code and the paper's: the value two Euler \
         half-steps reach, far above the peak, so that spike timing moves with \
         rounding-level changes of the input) or `capped` (at the peak, as in the \
         continuous model: the same spikes under such changes). See \
         docs/decisions/0031-overshoot-kept-by-default-capped-on-request.md.",
        get: shown,
        set: choice
    ),
    spec!(
        cutoff,
        Number,
        "Low-pass cutoff in Hz (zero-phase 2nd-order Butterworth); 0 turns the filter off."
    ),
    spec!(baseline, Text,
        "Baseline removal: `none`, or `min` (each taxel's minimum). Default: the dataset's \
         layout.toml.",
        get: |b: &Option<Baseline>| b.map(|b| b.to_string()),
        set: |t: &str| choice(t).map(Some)),
    spec!(whole, Flag, "Use the whole recording instead of only its sliding phase.",
        get: shown, set: flag),
    spec!(levels, Count, "Gray levels for GLCM quantisation."),
    spec!(bin_ms, Count, "Rate-volume bin and Fano window in ms."),
    spec!(distances, Counts, "GLCM offset distances, comma-separated.",
        get: |v: &Vec<usize>| Some(join(v)), set: counts),
    spec!(symmetric, Flag, "Count co-occurrences in both directions.",
        get: shown, set: flag),
    spec!(
        encoding,
        Text,
        "Mechanoreceptor populations: `sa` (slowly adapting, driven by the signal; the \
         paper's), `fa` (fast adapting, driven by its rectified rate of change) or `sa+fa` \
         (both, each with its own features, names prefixed `sa_` and `fa_`).",
        get: shown,
        set: choice
    ),
    spec!(
        fa_gain,
        Number,
        "Gain of the FA neurons from rate of change (normalised units per ms) to current; \
         the default gives FA neurons about the SA neurons' rate on a typical simulated slide."
    ),
    spec!(
        haralick,
        Text,
        "Haralick features of the GLCM methods: `paper` (contrast, correlation, ASM) or \
         `full` (the 13 of Haralick 1973, as mahotas defines them).",
        get: shown,
        set: choice
    ),
    spec!(bin_widths, Counts,
        "Rate-volume bin widths in ms of the `glcm3d-multi` method, comma-separated.",
        get: |v: &Vec<usize>| Some(join(v)), set: counts),
    spec!(
        window_mm,
        Number,
        "Fano window of the `all-taxels-mm` method, in mm of travel."
    ),
    spec!(
        spectrum_bins,
        Count,
        "Equal bins of travel the `spectrum` method counts each taxel's spikes in before \
         its Fourier transform (8 to 4096)."
    ),
    spec!(
        spectrum_bands,
        Count,
        "Logarithmically spaced bands of spatial frequency the `spectrum` method averages \
         the transform's magnitudes in (bands falling on the same frequency merge)."
    ),
    spec!(
        travel_mm,
        Number,
        "Span of the `spectrum` method in mm of travel from the start of the slide (needs \
         each recording's speed); 0 takes each recording's whole slide, whose frequencies \
         are then cycles per slide: spatial frequencies when every slide travels the same \
         distance."
    ),
    spec!(causal, Flag,
        "Condition causally, as a live stream can (`neurotex stream`): a forward-only \
         low-pass, and each taxel's resting value and one normalisation scale fixed on the \
         training recordings (labels unused) instead of the zero-phase filter and each \
         recording's own baseline and maximum, which need the whole recording.",
        get: shown, set: flag),
    spec!(
        drift_window_s,
        Number,
        "With --causal, track each taxel's resting value as the least of its input over \
         the last this many seconds (a multiple of 0.1 s; within 0.1 s) instead of fixing \
         it at training: for sensors whose resting level drifts between or within \
         recordings by more than their signal (capacitive skins). Longer than a contact, \
         so that the resting level before it stays in the window; 0 (the default) keeps \
         the fixed values."
    ),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_read_back_through_every_option_unchanged() {
        let mut o = StageOptions::default();
        for spec in STAGE_OPTIONS {
            if let Some(text) = spec.default_text() {
                (spec.set)(&mut o, &text).unwrap();
            }
        }
        assert_eq!(o, StageOptions::default());
        assert_eq!(o.check().unwrap().fixed(), Some(&PipelineParams::default()));
    }

    #[test]
    fn options_set_from_text_reach_the_checked_parameters() {
        let mut o = StageOptions::default();
        for (name, text) in [
            ("gain", "auto:15"),
            ("bin_ms", "100"),
            ("distances", "1,2"),
            ("symmetric", "true"),
            ("encoding", "sa+fa"),
            ("baseline", "min"),
            ("cutoff", "20.5"),
        ] {
            o.set(name, text).unwrap();
        }
        let c = o.check().unwrap();
        assert_eq!(c.gain_target(), Some(15.0));
        assert_eq!(c.fixed(), None, "the gain is still to be chosen");
        let p = c.to_calibrate();
        assert_eq!(p.volume.bin_ms, 100);
        assert_eq!(p.glcm.distances, [1, 2]);
        assert!(p.glcm.symmetric);
        assert_eq!(p.encoding, Encoding::SaFa);
        assert_eq!(p.preprocess.baseline, Some(Baseline::Min));
        assert_eq!(p.preprocess.cutoff_hz, 20.5);
        assert_eq!(p.encoder.gain, PipelineParams::default().encoder.gain);
    }

    #[test]
    fn bad_values_and_names_are_refused_with_what_was_expected() {
        let mut o = StageOptions::default();
        assert!(o.set("bin_ms", "-1").unwrap_err().contains("-1"));
        assert!(o.set("whole", "yes").unwrap_err().contains("true or false"));
        assert!(o.set("bin-ms", "2").unwrap_err().contains("bin_ms"));
        o.set("bin_ms", "0").unwrap();
        assert_eq!(o.check().unwrap_err().name, "bin-ms");
    }

    #[test]
    fn every_option_is_named_once_and_flags_are_its_kebab_spelling() {
        let mut names: Vec<&str> = STAGE_OPTIONS.iter().map(|o| o.name).collect();
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), STAGE_OPTIONS.len());
        assert_eq!(option("fa_gain").unwrap().flag(), "fa-gain");
    }
}
