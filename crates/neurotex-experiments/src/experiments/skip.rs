//! Why an analysis did not run, and how an analysis stops.

use crate::values::Speed;

/// A reason the data cannot support an analysis (or part of one).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Skip {
    /// E3 needs at least two taxels to move.
    #[error("fewer than 2 taxels to move")]
    TooFewTaxels,
    /// E3: counts of taxels to move beyond the grid's taxels, left out.
    #[error("the counts of taxels to move {} are left out: the grid has {taxels} taxels", list(.counts))]
    TaxelsBeyondTheGrid {
        /// The counts left out.
        counts: Vec<usize>,
        /// The grid's taxels.
        taxels: usize,
    },
    /// E6 trains on other speeds.
    #[error("the dataset has only one speed; E6 needs at least two")]
    OneSpeed,
    /// E9 compares within and across speeds.
    #[error("the dataset has only one speed; E9 compares within and across speeds")]
    OneSpeedE9,
    /// E9 compares the `sa+fa` encoding; address events without polarities have no OFF
    /// events for its FA population.
    #[error(
        "the address events have no polarity column, so no OFF events for E9's sa+fa candidates"
    )]
    NoOffEvents,
    /// E5c: the causal conditioning cannot be fixed on this speed's recordings.
    #[error("{reason}")]
    Causal {
        /// Speed.
        speed: Speed,
        /// The calibration's reason.
        reason: String,
    },
    /// The design is too small for the folds or neighbours asked for (the cross-validation
    /// within each speed that most analyses rest on, or E6's training speeds): the analysis
    /// cannot run. The key is the analysis's own.
    #[error("{reason}")]
    Design {
        /// The analysis's id (`e1`, `encoder sensitivity`).
        analysis: &'static str,
        /// Why, with what the design supports.
        reason: String,
    },
    /// E8: this `k` cannot be evaluated at this speed.
    #[error("{reason}")]
    Neighbours {
        /// Neighbours.
        k: usize,
        /// Speed.
        speed: Speed,
        /// The classifier's reason.
        reason: String,
    },
}

impl Skip {
    /// The key under which `results.json` lists the skip (`e3`, `e6`, `e8 k=9 at 5 mm/s`).
    pub fn key(&self) -> String {
        match self {
            Skip::TooFewTaxels => "e3".into(),
            Skip::TaxelsBeyondTheGrid { taxels, .. } => format!("e3 n > {taxels}"),
            Skip::OneSpeed => "e6".into(),
            Skip::OneSpeedE9 | Skip::NoOffEvents => "e9".into(),
            Skip::Causal { speed, .. } => format!("e5c at {speed} mm/s"),
            Skip::Neighbours { k, speed, .. } => format!("e8 k={k} at {speed} mm/s"),
            Skip::Design { analysis, .. } => (*analysis).into(),
        }
    }
}

/// `2, 3, 4` for the counts `[2, 3, 4]`.
fn list(counts: &[usize]) -> String {
    let all: Vec<String> = counts.iter().map(usize::to_string).collect();
    all.join(", ")
}

/// How an analysis stops early: skipped for a reason of the data, or failed.
#[derive(Debug, thiserror::Error)]
pub enum Stop {
    /// The data cannot support the analysis; the run goes on.
    #[error("skipped: {0}")]
    Skipped(Skip),
    /// The analysis failed; the run stops.
    #[error(transparent)]
    Failed(#[from] crate::Error),
}

impl Stop {
    /// This stop, a failure because the data is too small for the folds or neighbours
    /// asked for ([`crate::Error::is_design`]) turned into a skip of `analysis` with the
    /// reason: a larger run goes on without it.
    pub fn design_skipped(self, analysis: &'static str) -> Stop {
        match self {
            Stop::Failed(e) if e.is_design() => Stop::Skipped(Skip::Design {
                analysis,
                reason: e.to_string(),
            }),
            other => other,
        }
    }
}

impl From<Skip> for Stop {
    fn from(skip: Skip) -> Self {
        Stop::Skipped(skip)
    }
}
