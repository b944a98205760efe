//! Parameters of a reproduction run and their validated form (linfa's `ParamGuard`).

use crate::classify::{CvParams, Knn, KnnParams, ValidCv};
use crate::error::ParamError;
use crate::pipeline::{Pipeline, PipelineParams};

pub use crate::classify::cv::MAX_REPEATS;

/// Encodings per recording by default (see [`ReproduceParams::encodings`]).
/// Eight: on the paper-scale simulated default, each encoding past the first adds about
/// 4 % to a dataset's analyses (its encoding and headline evaluations; 9.8 s with one,
/// 13.1 s with nine on a 2-core EPYC), and eight bound the encoder's spread while the
/// first dataset stays under 15 s.
pub const DEFAULT_ENCODER_DRAWS: usize = 8;

/// Most encodings per recording one run accepts.
pub const MAX_ENCODER_DRAWS: usize = 100;

/// Parameters of a reproduction run; defaults are the paper's values, and where the paper
/// gives none, choices whose reasons docs/decisions/ gives.
#[derive(Debug, Clone, PartialEq)]
pub struct ReproduceParams {
    /// The pipeline (gain 8, 200 ms bins, 16 levels, distances 1, 2, 4, 8, ...).
    pub pipeline: PipelineParams,
    /// KNN (k = 5, z-scored).
    pub knn: KnnParams,
    /// Cross-validation (5 folds, seed, repeats).
    pub cv: CvParams,
    /// E3: random perturbations per n.
    pub e3_repeats: usize,
    /// E3: the numbers of taxels moved.
    pub e3_counts: Vec<usize>,
    /// E5: fractions of the slide used.
    pub e5_fractions: Vec<f64>,
    /// E7: the gain sweep at the slowest speed (ISI histograms); `false` skips it and its
    /// encodings, which are most of the encoder's work in a default run.
    pub e7: bool,
    /// E7: gains swept.
    pub e7_gains: Vec<f64>,
    /// E7: ISI histogram bin, ms.
    pub e7_bin_ms: u32,
    /// E7: ISI histogram range, ms (longer intervals share one last bin).
    pub e7_max_ms: u32,
    /// E8: neighbour counts.
    pub e8_ks: Vec<usize>,
    /// Seed of E3's perturbations.
    pub seed: u64,
    /// Encodings of every recording for the headline evaluations (E1, E4): the input as
    /// run, then `encodings - 1` times with an independent rounding-level perturbation
    /// (see `perturbation`). Their accuracies are averaged and their intervals resample
    /// encodings as well as recordings, so they hold the encoder's own sensitivity; 1
    /// evaluates the input as run only.
    pub encoder_draws: usize,
    /// The perturbations' size: each sample of a perturbed encoding's conditioned signal is
    /// multiplied by `1 + u * perturbation`, `u` uniform in [-1, 1) and independent per
    /// sample, encoding and recording (seeded by `seed`). Default 1e-12, far below any
    /// sensor's resolution and above the 2.2e-16 of a double's rounding.
    pub perturbation: f64,
    /// Cross-validation folds keep every group of this manifest column together (a run,
    /// a session, a subject); `None` folds recordings freely.
    pub group_by: Option<String>,
    /// E9 (beyond the paper): compare the standard candidates of `neurotex compare` per
    /// speed and with each speed held out; `false` skips it.
    pub e9: bool,
    /// E9: cross-validation repeats (each candidate gets the same folds).
    pub e9_repeats: usize,
    /// E9: also the spiking network (`snn` on the SA+FA spikes, its default
    /// hyperparameters) beside the paper's method on E9's folds, within each speed and with
    /// each speed held out. Off by default: it trains a network per fold, minutes on two
    /// cores.
    pub e9_snn: bool,
    /// E5c (beyond the paper): the causal pipeline's accuracy against time into the slide
    /// and its time to decision, beside the offline E5; `false` skips it.
    pub e5_causal: bool,
}

impl Default for ReproduceParams {
    fn default() -> Self {
        ReproduceParams {
            pipeline: PipelineParams::default(),
            knn: KnnParams::default(),
            cv: CvParams {
                folds: 5,
                seed: 0,
                repeats: 10,
            },
            e3_repeats: 10,
            e3_counts: (2..=16).collect(),
            e5_fractions: (1..=10).map(|k| k as f64 / 10.0).collect(),
            e7: true,
            e7_gains: (5..=20).map(f64::from).collect(),
            e7_bin_ms: 5,
            e7_max_ms: 300,
            e8_ks: vec![1, 3, 5, 7, 9],
            seed: 0,
            encoder_draws: DEFAULT_ENCODER_DRAWS,
            perturbation: 1e-12,
            group_by: None,
            e9: true,
            // One repeat: the intervals come from the bootstrap over recordings, and the
            // search over 34 candidates is the longest analysis of the run.
            e9_repeats: 1,
            e9_snn: false,
            e5_causal: true,
        }
    }
}

impl ReproduceParams {
    /// A smaller run for tests and CI: fewer repeats, perturbation counts, fractions and gains.
    pub fn quick() -> Self {
        ReproduceParams {
            cv: CvParams {
                folds: 5,
                seed: 0,
                repeats: 2,
            },
            e3_repeats: 3,
            e3_counts: vec![2, 4, 8, 16],
            e5_fractions: vec![0.2, 0.5, 1.0],
            e7_gains: vec![5.0, 8.0, 12.0, 20.0],
            e8_ks: vec![1, 5, 9],
            ..Self::default()
        }
    }

    /// The parameters as the report lists them, one `name: value` line each; `layout` the
    /// dataset's `layout.toml` baseline, which applies where the pipeline sets none, and
    /// `slides` the recordings with their slide's times in the manifest, of all.
    pub fn describe(
        &self,
        layout: Option<crate::recording::Baseline>,
        slides: [usize; 2],
    ) -> Vec<String> {
        self.pipeline
            .describe(layout, slides, &crate::pipeline::Method::ALL)
            .into_iter()
            .chain([
            format!(
                "KNN: k = {}, Euclidean, features z-scored on training folds: {}",
                self.knn.k, self.knn.standardize
            ),
            match &self.group_by {
                None => format!(
                    "CV: {}-fold stratified, shuffled with seed {}, {} repeats",
                    self.cv.folds, self.cv.seed, self.cv.repeats
                ),
                Some(column) => format!(
                    "CV: up to {} folds keeping each `{column}` group in one fold (each group held out in turn when there are fewer), seed {}, {} repeats",
                    self.cv.folds, self.cv.seed, self.cv.repeats
                ),
            },
            format!(
                "E3: {} draws per n, n in {:?}; E5 fractions {:?}; E7 gains {:?}; E8 k in {:?}",
                self.e3_repeats, self.e3_counts, self.e5_fractions, self.e7_gains, self.e8_ks
            ),
            if self.encoder_draws > 1 {
                format!(
                    "encoder sensitivity: E1, E4, E6 and E8 over {} encodings, the first as run and each other with every input sample times 1 + u x {:e} (u uniform in [-1, 1), independent per sample, seeded)",
                    self.encoder_draws, self.perturbation
                )
            } else {
                "encoder sensitivity: not measured (one encoding)".to_string()
            },
            ])
        .chain(self.e5_causal.then(|| {
            let rule = crate::causal::DecisionRule::default();
            format!(
                "E5c: causal conditioning (forward-only low-pass; resting values and scale fixed per speed on all of that speed's recordings, labels unused), a classification at every bin over the slide so far, E1's folds; decided at a share of {} of the vote in {} consecutive bins",
                rule.share, rule.bins
            )
        }))
        .chain(self.e9.then(|| {
            format!(
                "E9: the standard candidates of `neurotex compare` (encodings sa and sa+fa, FA gain {}), {}-fold CV with {} repeat(s) within each speed, and each speed held out with nested selection",
                self.pipeline.fa.gain, self.cv.folds, self.e9_repeats
            )
        }))
        .chain((self.e9 && self.e9_snn).then(|| {
            let snn = crate::snn::SnnParams::default();
            format!(
                "E9, spiking network: `snn` on the SA+FA spikes with its defaults (hidden {}, dt {} ms, at most {} epochs, {} readout over time, seed {}), E9's folds, no selection",
                snn.hidden, snn.dt_ms, snn.epochs, snn.readout.name(), snn.seed
            )
        }))
        .collect()
    }

    /// Checks every rule and plans the pipeline: the form the analyses take.
    ///
    /// # Errors
    /// The first rule broken, named by its option.
    pub fn check(self) -> Result<ValidReproduceParams, ParamError> {
        let pipeline = Pipeline::new(self.pipeline.clone())?;
        let knn = self.knn.check()?;
        let cv = self.cv.check()?;
        if cv.repeats > MAX_REPEATS {
            return Err(ParamError::new(
                "repeats",
                "repeats must be at most 10000",
                cv.repeats,
            ));
        }
        if !(1..=MAX_REPEATS).contains(&self.e3_repeats) {
            let rule = "E3 draws per n must be between 1 and 10000";
            return Err(ParamError::new("e3_repeats", rule, self.e3_repeats));
        }
        if let Some(&p) = self
            .e5_fractions
            .iter()
            .find(|p| !(**p > 0.0 && **p <= 1.0))
        {
            let rule = "E5 fractions of the slide must lie in (0, 1]";
            return Err(ParamError::new("e5_fractions", rule, p));
        }
        for &g in &self.e7_gains {
            self.pipeline.encoder.with_gain(g).check()?;
        }
        if self.e7_bin_ms == 0 || self.e7_max_ms < self.e7_bin_ms {
            let rule =
                "the E7 histogram needs a bin of at least 1 ms and a range of at least one bin";
            let got = format!("bin {} ms, range {} ms", self.e7_bin_ms, self.e7_max_ms);
            return Err(ParamError::new("e7_bin_ms", rule, got));
        }
        for &k in &self.e8_ks {
            KnnParams { k, ..self.knn }.check()?;
        }
        if !(1..=MAX_ENCODER_DRAWS).contains(&self.encoder_draws) {
            let rule = "encoder draws must be between 1 and 100";
            return Err(ParamError::new("encoder-draws", rule, self.encoder_draws));
        }
        if !(self.perturbation > 0.0 && self.perturbation < 1e-3) {
            let rule = "the perturbation must be a relative change above 0 and below 1e-3";
            return Err(ParamError::new("perturbation", rule, self.perturbation));
        }
        Ok(ValidReproduceParams {
            params: self,
            pipeline,
            knn,
            cv,
        })
    }
}

/// Parameters that passed [`ReproduceParams::check`], with the pipeline planned once and
/// the classifier and cross-validation in their validated forms.
#[derive(Debug, Clone)]
pub struct ValidReproduceParams {
    params: ReproduceParams,
    pipeline: Pipeline,
    knn: Knn,
    cv: ValidCv,
}

/// The encoder's sensitivity as asked for: how many encodings of each recording in all
/// (the first as run, the others perturbed), and the perturbations' seed and size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Draws {
    /// Encodings of each recording, the one as run included.
    pub encodings: usize,
    /// Seed of the perturbations' streams.
    pub seed: u64,
    /// Each perturbed sample is the sample times `1 + u * size`, `u` uniform in [-1, 1).
    pub size: f64,
}

impl ValidReproduceParams {
    /// The planned pipeline.
    pub fn pipeline(&self) -> &Pipeline {
        &self.pipeline
    }

    /// The encoder's sensitivity: `encoder_draws` encodings, perturbed by `perturbation`
    /// from streams of `seed`.
    pub fn draws(&self) -> Draws {
        Draws {
            encodings: self.encoder_draws,
            seed: self.seed,
            size: self.perturbation,
        }
    }

    /// The classifier at the run's `k`.
    pub fn knn(&self) -> &Knn {
        &self.knn
    }

    /// The classifier with `k` neighbours (E8); `k` was checked with the others.
    pub fn knn_with_k(&self, k: usize) -> Knn {
        KnnParams {
            k,
            ..self.knn.params()
        }
        .check()
        .unwrap_or(self.knn)
    }

    /// Cross-validation.
    pub fn cv(&self) -> ValidCv {
        self.cv
    }

    /// Cross-validation and the group column its folds keep together, as [`cv_at`] takes
    /// them.
    ///
    /// [`cv_at`]: super::tables::cv_at
    pub fn folds(&self) -> (ValidCv, Option<&str>) {
        (self.cv, self.params.group_by.as_deref())
    }

    /// Cross-validation with a single repeat (E3, E5 draw their spread elsewhere).
    pub fn cv_once(&self) -> ValidCv {
        CvParams {
            repeats: 1,
            ..*self.cv
        }
        .check()
        .unwrap_or(self.cv)
    }

    /// The same parameters without E5c, E7 and E9: what the further datasets of a run over
    /// several simulator seeds compute. Every dataset keeps the run's encodings, so each
    /// accuracy across the datasets is the same estimate (a mean over encodings where the
    /// first dataset's is one). E5c, E7 and E9 are reported for the first dataset only (no
    /// claim judged across the datasets reads them), so their work, most of the encoder's
    /// in E7's sweep, is left out.
    pub fn for_further_datasets(&self) -> Self {
        let mut quiet = self.clone();
        quiet.params.e5_causal = false;
        quiet.params.e7 = false;
        quiet.params.e9 = false;
        quiet
    }
}

impl std::ops::Deref for ValidReproduceParams {
    type Target = ReproduceParams;
    fn deref(&self) -> &ReproduceParams {
        &self.params
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rule_of(params: ReproduceParams) -> &'static str {
        params.check().err().map_or("none", |e| e.name)
    }

    #[test]
    fn each_rule_is_named_by_its_option() {
        let base = ReproduceParams::quick;
        assert_eq!(rule_of(base()), "none");
        assert_eq!(
            rule_of(ReproduceParams {
                e3_repeats: 0,
                ..base()
            }),
            "e3_repeats"
        );
        let e5_fractions = vec![0.5, 0.0];
        assert_eq!(
            rule_of(ReproduceParams {
                e5_fractions,
                ..base()
            }),
            "e5_fractions"
        );
        assert_eq!(
            rule_of(ReproduceParams {
                e5_fractions: vec![1.5],
                ..base()
            }),
            "e5_fractions"
        );
        assert_eq!(
            rule_of(ReproduceParams {
                e7_gains: vec![f64::NAN],
                ..base()
            }),
            "gain"
        );
        assert_eq!(
            rule_of(ReproduceParams {
                e7_bin_ms: 0,
                ..base()
            }),
            "e7_bin_ms"
        );
        assert_eq!(
            rule_of(ReproduceParams {
                e8_ks: vec![1, 0],
                ..base()
            }),
            "k"
        );
        let cv = CvParams {
            repeats: 0,
            ..CvParams::default()
        };
        assert_eq!(rule_of(ReproduceParams { cv, ..base() }), "repeats");
        let cv = CvParams {
            repeats: MAX_REPEATS + 1,
            ..CvParams::default()
        };
        assert_eq!(rule_of(ReproduceParams { cv, ..base() }), "repeats");
    }
}
