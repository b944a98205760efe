//! The classifiers' options, defined once as the stage options are: each knob's
//! classifier, name, flag, help and kind, its default read from the classifier's
//! parameters, and how its text sets them. The command line builds its flags from
//! [`CLASSIFIER_OPTIONS`] (`--snn-hidden`), Python its `classifier_options` keywords
//! (`hidden`), and [`classifier_with`] applies what either front end was given, so a
//! default or a rule is written here only.

use crate::classify::ClassifierChoice;
use crate::error::{Error, OptionsError};
use crate::snn::{Reset, SnnParams, Target};

use super::{choice, flag, parse, shown, OptionKind};

/// One classifier's knob.
pub struct KnobSpec {
    /// The classifier that takes it, as `--classifier` names it (`forest`).
    pub classifier: &'static str,
    /// Its name as Python spells it in `classifier_options` (`seed`).
    pub name: &'static str,
    /// The command line's flag (`--forest-seed`).
    pub flag: &'static str,
    /// What it does.
    pub help: &'static str,
    /// The kind of value it takes.
    pub kind: OptionKind,
    /// Its value in the classifier's parameters as text, as it is typed; `None` where it
    /// has none (a forest grown without a depth limit) or for another classifier.
    pub get: fn(&ClassifierChoice) -> Option<String>,
    /// Sets it in the classifier's parameters from text as it is typed; the error says
    /// what was expected.
    pub set: fn(&mut ClassifierChoice, &str) -> Result<(), String>,
}

impl KnobSpec {
    /// Its default as text, `None` when it has none.
    pub fn default_text(&self) -> Option<String> {
        (self.get)(&defaults_of(self.classifier))
    }

    /// Reads `text` as this knob takes it (on its classifier's defaults), without keeping
    /// it: the check each front end runs as a value is typed.
    ///
    /// # Errors
    /// What was expected, and what came.
    pub fn read(&self, text: &str) -> Result<(), String> {
        (self.set)(&mut defaults_of(self.classifier), text)
    }

    /// The help as the command line shows it: the classifier it applies to, what it does
    /// (its first word in lower case, unless an acronym), and its default (a small number
    /// in exponent form: `1e-8`).
    pub fn help_with_default(&self) -> String {
        let help = self.help.trim_end_matches('.');
        let mut chars = help.chars();
        let help = match (chars.next(), chars.next()) {
            (Some(first), Some(second)) if !second.is_uppercase() => {
                first.to_lowercase().chain(help.chars().skip(1)).collect()
            }
            _ => help.to_string(),
        };
        let with = format!("With `--classifier {}`: {help}", self.classifier);
        let default = match (self.kind, self.default_text()) {
            (OptionKind::Flag, _) | (_, None) => return with,
            (OptionKind::Number, Some(text)) => match text.parse::<f64>() {
                Ok(x) if x != 0.0 && x.abs() < 1e-3 => format!("{x:e}"),
                _ => text,
            },
            (_, Some(text)) => text,
        };
        format!("{with} [default: {default}]")
    }
}

impl std::fmt::Debug for KnobSpec {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KnobSpec")
            .field("classifier", &self.classifier)
            .field("name", &self.name)
            .finish()
    }
}

/// The classifier `name` with its default parameters (KNN for a name no classifier has:
/// the table names only real ones).
fn defaults_of(name: &str) -> ClassifierChoice {
    name.parse().unwrap_or_default()
}

/// The knobs of the classifier `name`, in the order `--help` lists them.
pub fn knobs_of(name: &str) -> impl Iterator<Item = &'static KnobSpec> + '_ {
    CLASSIFIER_OPTIONS
        .iter()
        .filter(move |k| k.classifier == name)
}

/// The classifier `kind` (its defaults) with the knobs `given` (each with its text)
/// applied, checked; without `reset`, the spiking network's Xylo target subtracts, as the
/// chip's neurons do.
///
/// # Errors
/// A knob of another classifier, a value a knob does not take, or a parameter out of its
/// range.
pub fn classifier_with(
    kind: ClassifierChoice,
    given: &[(&'static KnobSpec, String)],
) -> Result<ClassifierChoice, Error> {
    let mut choice = kind;
    let name = choice.name();
    for (spec, text) in given {
        if spec.classifier != name {
            return Err(OptionsError::NotApplicable {
                option: spec.flag,
                applies_to: applies_to(spec.classifier),
            }
            .into());
        }
        (spec.set)(&mut choice, text).map_err(|reason| OptionsError::Invalid {
            option: spec.flag,
            reason,
        })?;
    }
    if let ClassifierChoice::Snn(p) = &mut choice {
        if p.target == Target::Xylo && !given.iter().any(|(s, _)| s.flag == "--snn-reset") {
            p.reset = Reset::Subtract;
        }
        return Ok(ClassifierChoice::Snn(p.check()?));
    }
    choice.check()?;
    Ok(choice)
}

/// `--classifier NAME` for the classifier `name`.
fn applies_to(name: &str) -> &'static str {
    match name {
        "knn" => "--classifier knn",
        "forest" => "--classifier forest",
        "linear" => "--classifier linear",
        _ => "--classifier snn",
    }
}

/// The spiking network's parameters `defaults` with the knobs `given` applied, checked
/// ([`classifier_with`] for the network alone).
///
/// # Errors
/// As [`classifier_with`].
pub fn snn_with(
    defaults: SnnParams,
    given: &[(&'static KnobSpec, String)],
) -> Result<SnnParams, Error> {
    match classifier_with(ClassifierChoice::Snn(defaults), given)? {
        ClassifierChoice::Snn(p) => Ok(p),
        other => unreachable!("the network's knobs made a {}", other.name()),
    }
}

/// The spec of one field of one classifier's parameters.
macro_rules! knob {
    ($variant:ident $classifier:literal, $field:ident, $flag:literal, $kind:ident, $help:expr,
     get: $get:expr, set: $set:expr) => {
        KnobSpec {
            classifier: $classifier,
            name: stringify!($field),
            flag: $flag,
            help: $help,
            kind: OptionKind::$kind,
            get: |c: &ClassifierChoice| match c {
                ClassifierChoice::$variant(p) => ($get)(&p.$field),
                _ => None,
            },
            set: |c: &mut ClassifierChoice, t: &str| match c {
                ClassifierChoice::$variant(p) => {
                    p.$field = ($set)(t)?;
                    Ok(())
                }
                _ => Err(format!("applies only to the classifier {}", $classifier)),
            },
        }
    };
    ($variant:ident $classifier:literal, $field:ident, $flag:literal, $kind:ident, $help:expr) => {
        knob!($variant $classifier, $field, $flag, $kind, $help, get: shown, set: parse)
    };
}

/// A count that may be absent, `None` standing for the rule its help names.
fn some_count(text: &str) -> Result<Option<usize>, String> {
    parse(text).map(Some)
}

/// A count that may be absent, as it is typed.
fn shown_some(value: &Option<usize>) -> Option<String> {
    value.map(|v| v.to_string())
}

/// Every classifier's knobs: KNN's, the forest's, the regression's, the network's.
pub static CLASSIFIER_OPTIONS: &[KnobSpec] = &[
    knob!(Knn "knn", k, "--k", Count,
        "Neighbours in KNN; at most the number of recordings in a training set."),
    knob!(Knn "knn", standardize, "--standardize", Bool,
        "Z-score features with training-fold statistics before KNN (the command line's \
         --no-standardize turns it off).", get: shown, set: flag),
    knob!(Forest "forest", trees, "--trees", Count, "Trees in the forest."),
    knob!(Forest "forest", seed, "--forest-seed", Count, "Seed of the trees' random streams."),
    knob!(Forest "forest", max_depth, "--max-depth", Count,
        "Deepest level of a tree, the root at 0 [default: grown until leaves are pure or \
         too small to split].",
        get: shown_some, set: some_count),
    knob!(Forest "forest", min_samples_leaf, "--min-samples-leaf", Count,
        "Fewest training recordings in a leaf."),
    knob!(Forest "forest", max_features, "--max-features", Count,
        "Features tried at each split [default: ⌊√d⌋].",
        get: shown_some, set: some_count),
    knob!(Forest "forest", bootstrap, "--bootstrap", Bool,
        "Grow each tree on a bootstrap sample (`true`) or on the whole training set \
         (`false`).", get: shown, set: flag),
    knob!(Linear "linear", c, "--c", Number,
        "Inverse penalty strength, scikit-learn's C."),
    knob!(Linear "linear", max_iter, "--max-iter", Count, "Most L-BFGS iterations."),
    knob!(Linear "linear", tol, "--tol", Number,
        "Stop when no gradient component exceeds this."),
    knob!(Snn "snn", hidden, "--snn-hidden", Count, "Hidden LIF neurons."),
    knob!(Snn "snn", dt_ms, "--snn-dt-ms", Count,
        "The network's time step in ms; the encoder's 1 ms spikes are counted in bins this \
         wide."),
    knob!(Snn "snn", epochs, "--snn-epochs", Count,
        "Most training epochs; early stopping on a validation split of the training \
         recordings may end sooner."),
    knob!(Snn "snn", readout, "--snn-readout", Text,
        "Class scores are the readout's `mean` over time or its `max`.",
        get: |r: &crate::snn::Readout| Some(r.name().to_string()), set: choice),
    knob!(Snn "snn", seed, "--snn-seed", Count,
        "Seed of the initial weights, validation split and batch order."),
    knob!(Snn "snn", recurrent, "--snn-recurrent", Flag,
        "Recurrent connections within the hidden layer (each step's spikes drive the next \
         step's currents); feed-forward without it.", get: shown, set: flag),
    knob!(Snn "snn", reset, "--snn-reset", Text,
        "How a hidden neuron resets on a spike: `zero` (one spike per step at most) or \
         `subtract` (n = floor(v) spikes, v - n kept: the neuron of sinabs, Rockpool and \
         Xylo, needed to export to them; the default under `--snn-target xylo`).",
        get: |r: &Reset| Some(r.name().to_string()), set: choice),
    knob!(Snn "snn", tau_syn_ms, "--snn-tau-syn-ms", Number,
        "The hidden neurons' synaptic time constant, ms."),
    knob!(Snn "snn", tau_mem_ms, "--snn-tau-mem-ms", Number,
        "The hidden neurons' membrane time constant, ms."),
    knob!(Snn "snn", tau_out_ms, "--snn-tau-out-ms", Number, "The readout's time constant, ms."),
    knob!(Snn "snn", window_ms, "--snn-window-ms", Count,
        "Train on windows of this many ms (rounded down to whole network steps) cut from \
         the training recordings, each drawn anew at every epoch from anywhere in its \
         recording: an epoch's cost no longer grows with the slides' length, and the network \
         learns from every part of a slide [default: whole recordings]. Validation and \
         prediction read whole recordings.",
        get: shown_some, set: some_count),
    knob!(Snn "snn", standardize, "--snn-standardize", Bool,
        "Train on inputs standardised by their mean and spread over the training recordings \
         (`true`: measured higher within a condition, lower on a held-out speed of the \
         simulator), or on the spike counts as they are (`false`).", get: shown, set: flag),
    knob!(Snn "snn", train_decays, "--snn-train-decays", Flag,
        "Train each hidden neuron's synaptic and membrane decays beside the weights \
         (learnable time constants): each neuron starts from time constants drawn about \
         --snn-tau-syn-ms and --snn-tau-mem-ms (gamma, shape 3) and finds the time scales it \
         reads its inputs' timing at; without it the neurons share those two constants.",
        get: shown, set: flag),
    knob!(Snn "snn", travel, "--snn-travel", Text,
        "Count the network's time in travel: a recording slid at v mm/s is binned in steps \
         of --snn-dt-ms x V / |v| ms (1 to 1000 ms), so that each step covers the distance --snn-dt-ms covers \
         at V and a texture's pattern takes the same steps at every speed (the time \
         constants hold at V); each spike weighs |v| / V, so a step's input stays a rate. \
         `median`: V is the training recordings' median speed (time in ms when a recording \
         has no speed; trained at one speed, the network is the same as in ms); a number: \
         that V, mm/s; `off`: steps of --snn-dt-ms whatever the speed. A stream knows no \
         speed: it steps the network as for a slide at V.",
        get: |t: &crate::snn::Travel| Some(t.name()), set: choice),
    knob!(Snn "snn", warp, "--snn-warp", Number,
        "Train on time-warped recordings: at each epoch each training recording is \
         stretched or squeezed by a factor drawn log-uniformly between 1/W and W (above 1, \
         at most 10), as if slid up to W times slower or faster with the same spikes per mm, \
         so that the network meets each texture at more speeds than it was recorded at; \
         validation and prediction read the recordings as they are [default: none: no \
         warp].",
        get: |w: &Option<f64>| w.map(|v| v.to_string()), set: |t: &str| parse(t).map(Some)),
    knob!(Snn "snn", adapt_ms, "--snn-adapt-ms", Number,
        "Adaptive thresholds (ALIF): each hidden neuron's threshold rises by \
         --snn-adapt-strength times its spike rate over about this many ms and falls back \
         as it stays silent, so that a neuron answers change more than a steady drive. \
         Neurons reset to zero (refused with --snn-reset subtract and --snn-target xylo), \
         and NIR has no adaptive threshold: `export nir` refuses such a network, which runs \
         from its model file [default: none: fixed thresholds].",
        get: |w: &Option<f64>| w.map(|v| v.to_string()), set: |t: &str| parse(t).map(Some)),
    knob!(Snn "snn", adapt_strength, "--snn-adapt-strength", Number,
        "With --snn-adapt-ms: how far a threshold of 1 rises at a spike every step (1: it \
         doubles)."),
    knob!(Snn "snn", delay_ms, "--snn-delay-ms", Number,
        "Learnable synaptic delays: each input synapse carries its spikes up to this many ms \
         late, its delay trained beside its weight, so that a hidden neuron can line up \
         spikes its inputs sent at different times (a pattern reaching neighbouring taxels \
         one after the other). One to 1000 time steps of --snn-dt-ms (of travel, with \
         --snn-travel: ms at its reference speed). Refused by the Xylo profile and NIR \
         export [default: none: no delays].",
        get: |w: &Option<f64>| w.map(|v| v.to_string()), set: |t: &str| parse(t).map(Some)),
    knob!(Snn "snn", target, "--snn-target", Text,
        "Where the network runs: `float` or `xylo` (SynSense's Xylo Audio 2: trained within \
         the chip's limits, its time constants moved to the chip's bitshift decays, \
         subtractive reset, and predicting in the chip's integers as its simulator does; \
         `export xylo` writes its configuration).",
        get: |t: &Target| Some(t.name().to_string()), set: choice),
];

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_read_back_through_every_knob_unchanged() {
        for name in ["knn", "forest", "linear", "snn"] {
            let defaults = defaults_of(name);
            let given: Vec<(&'static KnobSpec, String)> = knobs_of(name)
                .filter_map(|k| k.default_text().map(|t| (k, t)))
                .collect();
            assert_eq!(classifier_with(defaults, &given).unwrap(), defaults);
        }
    }

    #[test]
    fn knobs_set_from_text_reach_the_parameters_and_others_are_refused() {
        let knob = |flag: &str| {
            CLASSIFIER_OPTIONS
                .iter()
                .find(|k| &k.flag[2..] == flag)
                .unwrap()
        };
        let given = [
            (knob("trees"), "3".to_string()),
            (knob("max-depth"), "2".into()),
        ];
        let forest = classifier_with(defaults_of("forest"), &given).unwrap();
        let ClassifierChoice::Forest(p) = forest else {
            panic!("a forest")
        };
        assert_eq!((p.trees, p.max_depth), (3, Some(2)));
        let e = classifier_with(defaults_of("knn"), &given).unwrap_err();
        assert_eq!(e.to_string(), "--trees applies only to --classifier forest");
        let zero = [(knob("snn-hidden"), "0".to_string())];
        let e = classifier_with(defaults_of("snn"), &zero).unwrap_err();
        assert!(e.to_string().contains("snn-hidden"), "{e}");
        let bad = [(knob("snn-readout"), "median".to_string())];
        assert!(classifier_with(defaults_of("snn"), &bad).is_err());
    }

    #[test]
    fn the_help_names_the_classifier_and_the_default_read_from_its_parameters() {
        let help = |flag: &str| {
            let knob = CLASSIFIER_OPTIONS.iter().find(|k| &k.flag[2..] == flag);
            knob.unwrap().help_with_default()
        };
        assert_eq!(help("tol"), "With `--classifier linear`: stop when no gradient component exceeds this [default: 1e-8]");
        assert_eq!(
            help("trees"),
            "With `--classifier forest`: trees in the forest [default: 200]"
        );
        assert!(help("max-depth").ends_with("too small to split]"));
        assert!(help("snn-recurrent").ends_with("feed-forward without it"));
    }

    #[test]
    fn the_xylo_target_subtracts_unless_told_otherwise() {
        let knob = |flag: &str| {
            CLASSIFIER_OPTIONS
                .iter()
                .find(|k| &k.flag[2..] == flag)
                .unwrap()
        };
        let xylo = [(knob("snn-target"), "xylo".to_string())];
        let ClassifierChoice::Snn(p) = classifier_with(defaults_of("snn"), &xylo).unwrap() else {
            panic!("a network")
        };
        assert_eq!(p.reset, Reset::Subtract);
        let zero = [xylo[0].clone(), (knob("snn-reset"), "zero".to_string())];
        assert!(classifier_with(defaults_of("snn"), &zero).is_err());
    }

    #[test]
    fn every_knob_is_named_once_per_classifier_and_flags_once() {
        let mut flags: Vec<&str> = CLASSIFIER_OPTIONS.iter().map(|k| k.flag).collect();
        flags.sort_unstable();
        flags.dedup();
        assert_eq!(flags.len(), CLASSIFIER_OPTIONS.len());
        for k in CLASSIFIER_OPTIONS {
            assert_eq!(
                knobs_of(k.classifier).filter(|o| o.name == k.name).count(),
                1
            );
        }
    }
}
