//! `benchmark`: the public datasets' leaderboards. Each dataset is fetched by its recipe,
//! and under each protocol the recipe names a fixed, versioned candidate set is compared
//! with nested selection, exactly as `compare --nested` compares it; the leaderboard sets
//! the published results beside ours. A finished dataset x protocol is kept, and a rerun
//! with the same settings reuses it; within a protocol, each candidate's finished scores
//! are kept as they come, so that a run stopped part way resumes where it stopped.

mod leaderboard;
mod pieces;

use pieces::Pieces;

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use super::compare::CompareOptions;
use super::{KnnOptions, OnProgress, OpenOptions, SnnOptions};
use crate::compare::candidates::{
    STANDARD_CLASSIFIERS, STANDARD_ENCODINGS, STANDARD_METHODS, STANDARD_TAU_MS,
};
use crate::compare::signal::NO_ENCODING;
use crate::compare::Comparison;
use crate::datasets::{self, ProtocolSpec, Published, Recipe};
use crate::error::DataError;
use crate::io::write_atomic;
use crate::options::StageOptions;
use crate::progress::Progress;
use crate::Result;

pub use leaderboard::{markdown, Board, Leaderboard};

/// The version of the candidate set below: raised whenever it changes, so that a kept result
/// of another set is never reused or compared as if it were the same.
pub const CANDIDATE_SET_VERSION: u32 = 1;

/// The candidate set, written down: `compare`'s standard encodings and the baselines
/// without spikes (`none`), its standard methods and the spike counts (`rates`), its
/// standard classifiers; `--snn` adds the spiking network on the spike trains.
pub fn candidate_set(snn: bool) -> (String, String, String) {
    let methods = match snn {
        true => format!("{STANDARD_METHODS},rates,spikes"),
        false => format!("{STANDARD_METHODS},rates"),
    };
    let classifiers = match snn {
        true => format!("{STANDARD_CLASSIFIERS},snn"),
        false => STANDARD_CLASSIFIERS.to_string(),
    };
    (
        format!("{STANDARD_ENCODINGS},{NO_ENCODING}"),
        methods,
        classifiers,
    )
}

/// Options of `neurotex benchmark`.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Args))]
pub struct BenchmarkOptions {
    /// Datasets: built-in recipes by name (`neurotex datasets list`) or recipe files.
    #[cfg_attr(feature = "cli", arg(required = true))]
    pub datasets: Vec<String>,
    /// The folder to write leaderboard.md, leaderboard.json and, per dataset and protocol,
    /// the comparison (compare.json, compare.md, figures). A rerun into it keeps what is
    /// finished, down to the candidates' scores of a protocol stopped part way.
    #[cfg_attr(feature = "cli", arg(long))]
    pub out: PathBuf,
    /// The cache of fetched datasets (default: $NEUROTEX_CACHE, else
    /// $XDG_CACHE_HOME/neurotex, else ~/.cache/neurotex).
    #[cfg_attr(feature = "cli", arg(long))]
    pub cache: Option<PathBuf>,
    /// A local copy of the sources of a dataset not yet in the cache (one dataset only),
    /// instead of downloading them: a folder of the downloaded files, a one-source recipe's
    /// file itself, or the unpacked folder a recipe's tree digest checks.
    #[cfg_attr(feature = "cli", arg(long))]
    pub from: Option<PathBuf>,
    /// Only these protocols (their ids in the recipes, comma-separated); default all.
    #[cfg_attr(feature = "cli", arg(long, value_delimiter = ','))]
    pub protocols: Vec<String>,
    /// Also the spiking network with its defaults (method `spikes`; slow on long slides).
    #[cfg_attr(feature = "cli", arg(long))]
    pub snn: bool,
    /// Cross-validation folds.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = crate::classify::CvParams::default().folds))]
    pub folds: usize,
    /// Cross-validation repeats.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = crate::classify::CvParams::default().repeats))]
    pub repeats: usize,
    /// Seed of the folds, the bootstrap and the tests.
    #[cfg_attr(feature = "cli", arg(long, default_value_t = 0))]
    pub seed: u64,
}

/// What decides one dataset x protocol's result: a kept result is reused only under the
/// same key.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
struct Key {
    recipe: String,
    import_digest: String,
    protocol: String,
    candidate_set: u32,
    /// [`crate::compare::NESTED_VERSION`].
    #[serde(default)]
    nested: u32,
    snn: bool,
    folds: usize,
    repeats: usize,
    seed: u64,
    neurotex: String,
}

impl Key {
    /// As its key file holds it.
    fn text(&self) -> String {
        serde_json::to_string_pretty(self).unwrap_or_default()
    }
}

impl BenchmarkOptions {
    /// Fetches every dataset (checking every recipe first), compares under each protocol,
    /// writes the leaderboard into `--out` and returns it.
    ///
    /// # Errors
    /// A recipe that is not valid, `--from` with several datasets, a dataset that cannot be
    /// fetched, a comparison that cannot run, or an output that cannot be written.
    pub fn run(&self, on: OnProgress) -> Result<Leaderboard> {
        let recipes = self.recipes()?;
        let root = datasets::cache_root(self.cache.as_deref())?;
        let mut boards = Vec::new();
        for recipe in &recipes {
            let dataset = datasets::fetch(recipe, &root, self.from.as_deref(), on)?;
            for (i, protocol) in recipe.protocols.iter().enumerate() {
                if !self.protocols.is_empty() && !self.protocols.contains(&protocol.id) {
                    continue;
                }
                on(Progress::Say(&format!(
                    "{}: {} ({} of {})",
                    recipe.name,
                    protocol.describe(),
                    i + 1,
                    recipe.protocols.len()
                )));
                let comparison = self.protocol(recipe, &dataset, i, on)?;
                let published: Vec<Published> = (recipe.published.iter())
                    .filter(|p| p.beside == protocol.id)
                    .cloned()
                    .collect();
                boards.push(Board::of(recipe, protocol, comparison, published));
            }
        }
        let board = Leaderboard {
            candidate_set: CANDIDATE_SET_VERSION,
            seed: self.seed,
            folds: self.folds,
            repeats: self.repeats,
            snn: self.snn,
            neurotex: env!("CARGO_PKG_VERSION").to_string(),
            boards,
        };
        board.write(&self.out)?;
        Ok(board)
    }

    /// Every id of `--protocols` is a protocol of some recipe.
    fn check_protocols(&self, recipes: &[Recipe]) -> Result<()> {
        let ids: Vec<&str> = (recipes.iter())
            .flat_map(|r| r.protocols.iter().map(|p| p.id.as_str()))
            .collect();
        match self.protocols.iter().find(|p| !ids.contains(&p.as_str())) {
            Some(unknown) => Err(crate::error::ParamError::new(
                "protocols",
                "each must be a protocol id of the recipes",
                format!("{unknown} (the recipes have {})", ids.join(", ")),
            )
            .into()),
            None => Ok(()),
        }
    }

    /// The key of `recipe`'s `protocol` under these settings.
    fn key(&self, recipe: &Recipe, protocol: &ProtocolSpec) -> Key {
        Key {
            recipe: recipe.name.clone(),
            import_digest: recipe.import_digest(),
            protocol: serde_json::to_string(protocol).unwrap_or_default(),
            candidate_set: CANDIDATE_SET_VERSION,
            nested: crate::compare::NESTED_VERSION,
            snn: self.snn,
            folds: self.folds,
            repeats: self.repeats,
            seed: self.seed,
            neurotex: env!("CARGO_PKG_VERSION").to_string(),
        }
    }

    /// `compare --nested` over the candidate set (of `encodings` only, when given) under
    /// `protocol` on `dataset`.
    fn compare(
        &self,
        protocol: &ProtocolSpec,
        dataset: &Path,
        share: Option<&Share>,
    ) -> CompareOptions {
        let (all, all_methods, classifiers) = candidate_set(self.snn);
        let encodings = share.map(|s| s.encoding.as_str());
        let methods = share.and_then(|s| s.method.clone()).unwrap_or(all_methods);
        let list = |s: &str| s.split(',').map(String::from).collect();
        CompareOptions {
            dataset: dataset.to_path_buf(),
            speeds: None,
            per: protocol.per.clone(),
            hold_out: protocol.hold_out.clone(),
            train_where: None,
            test_where: None,
            group_by: None,
            encodings: list(encodings.unwrap_or(&all)),
            methods: list(&methods),
            classifiers: list(&classifiers),
            tau_ms: STANDARD_TAU_MS,
            knn: KnnOptions::default(),
            snn: SnnOptions::default(),
            folds: self.folds,
            repeats: self.repeats,
            seed: self.seed,
            nested: true,
            inner_folds: None,
            encoder_draws: 1,
            open: OpenOptions::default(),
        }
    }

    /// The folder of the kept pieces of `recipe`'s `protocol`.
    fn pieces_dir(&self, recipe: &Recipe, protocol: &ProtocolSpec) -> PathBuf {
        (self.out.join(&recipe.name)).join(format!("{}.pieces", protocol.id))
    }

    /// The folder of `recipe`'s `protocol`'s comparison (compare.json, compare.md, figures).
    fn comparison_dir(&self, recipe: &Recipe, protocol: &ProtocolSpec) -> PathBuf {
        (self.out.join(&recipe.name)).join(&protocol.id)
    }

    /// The key file of `recipe`'s `protocol`'s comparison, beside its folder.
    fn key_file(&self, recipe: &Recipe, protocol: &ProtocolSpec) -> PathBuf {
        (self.out.join(&recipe.name)).join(format!("{}.key.json", protocol.id))
    }

    /// The comparison of `recipe`'s `protocol` kept under `key`, if there is one.
    fn kept(&self, recipe: &Recipe, protocol: &ProtocolSpec, key: &Key) -> Option<Comparison> {
        let text = std::fs::read_to_string(self.key_file(recipe, protocol)).ok()?;
        let found: Key = serde_json::from_str(&text).ok()?;
        if &found != key {
            return None;
        }
        let dir = self.comparison_dir(recipe, protocol);
        let json = std::fs::read_to_string(dir.join("compare.json")).ok()?;
        serde_json::from_str(&json).ok()
    }

    /// `compare --nested` of the candidate set (of `encodings` only, when given) under
    /// `recipe`'s `protocol` on `dataset`, taking and keeping its pieces in `pieces`.
    fn compare_keeping(
        &self,
        (recipe, protocol): (&Recipe, &ProtocolSpec),
        (dataset, share): (&Path, Option<&Share>),
        pieces: &Pieces,
        on: OnProgress,
    ) -> Result<Comparison> {
        let options = self.compare(protocol, dataset, share);
        let opened = options.open.open(dataset)?;
        // A warning names its dataset and protocol: where only warnings are shown (Python's
        // default logging), nothing else says which comparison it is about.
        let named = |p: Progress| match p {
            Progress::Advice(text) => on(Progress::Advice(&format!(
                "{}, {}: {text}",
                recipe.name, protocol.id
            ))),
            other => on(other),
        };
        options
            .run_keeping(&opened, &StageOptions::default(), &named, Some(pieces))
            .map_err(|e| crate::Error::InAnalysis {
                what: format!("{}, {}", recipe.name, protocol.describe()),
                source: Box::new(e),
            })
    }

    /// The comparison of `recipe`'s protocol `i` on `dataset`: the kept one under the same
    /// key, else compared anew (taking the pieces a run stopped part way kept) and kept.
    fn protocol(
        &self,
        recipe: &Recipe,
        dataset: &Path,
        i: usize,
        on: OnProgress,
    ) -> Result<Comparison> {
        let protocol = &recipe.protocols[i];
        let key = self.key(recipe, protocol);
        if let Some(kept) = self.kept(recipe, protocol, &key) {
            on(Progress::Say(
                "  kept from an earlier run with the same settings",
            ));
            return Ok(kept);
        }
        let key_text = key.text();
        let pieces = Pieces::open(self.pieces_dir(recipe, protocol), &key_text)?;
        if pieces.removed > 0 {
            let differed = match pieces.differed.is_empty() {
                true => String::new(),
                false => format!(" ({})", pieces.differed.join(", ")),
            };
            on(Progress::Say(&format!(
                "  {} finished pieces of a stopped run with other settings{differed} removed",
                pieces.removed
            )));
        }
        if pieces.held > 0 {
            on(Progress::Say(&format!(
                "  {} finished pieces found, kept by a run stopped part way (or by shares): taken up, not computed again",
                pieces.held
            )));
        }
        let comparison = self.compare_keeping((recipe, protocol), (dataset, None), &pieces, on)?;
        if pieces.taken() > 0 {
            on(Progress::Say(&format!(
                "  {} finished pieces taken (kept by a run stopped part way, or by shares)",
                pieces.taken()
            )));
        }
        // The figures name the dataset by its recipe, not by the cache's folder.
        let named = Path::new(&recipe.name);
        // The old key goes first: a run stopped between the two writes leaves no key, never
        // another run's key beside this comparison.
        let (dir, key_file) = (
            self.comparison_dir(recipe, protocol),
            self.key_file(recipe, protocol),
        );
        if key_file.exists() {
            std::fs::remove_file(&key_file).map_err(|e| DataError::write(&key_file, e))?;
        }
        crate::report::comparison::write_comparison(&dir, &comparison, named)?;
        write_atomic(&key_file, |w| w.write_all(key_text.as_bytes()))?;
        pieces.finish();
        Ok(comparison)
    }

    /// The shares of the work that separate tasks (on a cluster) can compute side by side:
    /// each dataset x protocol not yet kept, split by the candidate set's encodings and, for
    /// each spike encoding, by its feature methods (each share encodes its recordings once,
    /// so a share's own work is its method's candidates under every classifier; the
    /// baselines without spikes are one share). Fetches every dataset and makes each protocol's
    /// pieces folder, so that the shares find it made; [`BenchmarkOptions::run`] then
    /// takes what they kept.
    ///
    /// # Errors
    /// As [`BenchmarkOptions::run`]'s checks and fetches.
    pub fn shares(&self, on: OnProgress) -> Result<Vec<Share>> {
        let recipes = self.recipes()?;
        let root = datasets::cache_root(self.cache.as_deref())?;
        let (encodings, methods, _) = candidate_set(self.snn);
        let mut shares = Vec::new();
        for (named, recipe) in self.datasets.iter().zip(&recipes) {
            datasets::fetch(recipe, &root, self.from.as_deref(), on)?;
            for protocol in self.wanted(recipe) {
                let key = self.key(recipe, protocol);
                if self.kept(recipe, protocol, &key).is_some() {
                    continue;
                }
                Pieces::open(self.pieces_dir(recipe, protocol), &key.text())?;
                for encoding in encodings.split(',') {
                    // The baselines without spikes read no spike method: one share.
                    let each: Vec<Option<String>> = match encoding == NO_ENCODING {
                        true => vec![None],
                        false => methods.split(',').map(|m| Some(m.to_string())).collect(),
                    };
                    shares.extend(each.into_iter().map(|method| Share {
                        dataset: recipe.name.clone(),
                        recipe: named.clone(),
                        protocol: protocol.id.clone(),
                        encoding: encoding.to_string(),
                        method,
                    }));
                }
            }
        }
        Ok(shares)
    }

    /// Computes and keeps one share's pieces (its candidates' scores and their accuracies
    /// inside nested selection's outer splits), for [`BenchmarkOptions::run`] to take.
    ///
    /// # Errors
    /// The share's dataset not fetched, its pieces folder not made for these settings (by
    /// [`BenchmarkOptions::shares`]), or a comparison that cannot run.
    pub fn run_share(&self, share: &Share, on: OnProgress) -> Result<()> {
        let recipe = datasets::resolve(&share.recipe)?;
        let root = datasets::cache_root(self.cache.as_deref())?;
        let dataset = datasets::fetched(&root, &recipe).ok_or_else(|| {
            let why = "not fetched: `neurotex datasets fetch` it first".to_string();
            DataError::invalid(datasets::entry(&root, &recipe), why)
        })?;
        let Some(protocol) = recipe.protocols.iter().find(|p| p.id == share.protocol) else {
            let why = format!("{} has no protocol {}", recipe.name, share.protocol);
            return Err(crate::error::OptionsError::Conflict(why).into());
        };
        let key = self.key(&recipe, protocol);
        let pieces = Pieces::existing(self.pieces_dir(&recipe, protocol), &key.text())?;
        let share_of = (dataset.as_path(), Some(share));
        self.compare_keeping((&recipe, protocol), share_of, &pieces, on)?;
        Ok(())
    }

    /// The recipes of `--datasets`, checked.
    fn recipes(&self) -> Result<Vec<Recipe>> {
        let recipes: Vec<Recipe> = (self.datasets.iter())
            .map(|d| datasets::resolve(d))
            .collect::<Result<_>>()?;
        if self.from.is_some() && recipes.len() > 1 {
            let why = "--from is the copy of one dataset's sources: benchmark one dataset with it, or fetch each first (`neurotex datasets fetch`)";
            return Err(crate::error::OptionsError::Conflict(why.into()).into());
        }
        self.check_protocols(&recipes)?;
        Ok(recipes)
    }

    /// `recipe`'s protocols that `--protocols` asks for.
    fn wanted<'r>(&self, recipe: &'r Recipe) -> Vec<&'r ProtocolSpec> {
        (recipe.protocols.iter())
            .filter(|p| self.protocols.is_empty() || self.protocols.contains(&p.id))
            .collect()
    }
}

/// A share of a benchmark's work ([`BenchmarkOptions::shares`]): one encoding's candidates
/// (of one method, or all) under one protocol of one dataset.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Share {
    /// The recipe's name.
    pub dataset: String,
    /// The dataset as `--datasets` named it (a built-in name or a recipe file).
    pub recipe: String,
    /// The protocol's id.
    pub protocol: String,
    /// The encoding (`sa`, `sa+fa`, `none`).
    pub encoding: String,
    /// The feature method whose candidates the share computes (every classifier's); `None`
    /// for every method of the encoding (the baselines of `none`).
    pub method: Option<String>,
}

impl Leaderboard {
    /// Writes leaderboard.json, leaderboard.md and the figure (SVG and PNG) into `out`.
    ///
    /// # Errors
    /// A file cannot be written.
    pub fn write(&self, out: &Path) -> Result<()> {
        std::fs::create_dir_all(out).map_err(|e| DataError::write(out, e))?;
        let json = serde_json::to_string_pretty(self)
            .map_err(|e| DataError::invalid(out.join("leaderboard.json"), e.to_string()))?;
        write_atomic(&out.join("leaderboard.json"), |w| {
            w.write_all((json + "\n").as_bytes())
        })?;
        let groups: Vec<_> = self.boards.iter().map(Board::figure_group).collect();
        let svg = crate::report::figures::leaderboard::leaderboard(&groups, "neurotex benchmark")
            .map_err(|e| DataError::invalid(out.join("leaderboard.svg"), e.to_string()))?;
        let files = crate::report::figures::svg_and_png("leaderboard.svg", svg)
            .map_err(|e| DataError::invalid(out.join("leaderboard.svg"), e.to_string()))?;
        for (name, bytes) in files {
            write_atomic(&out.join(&name), |w| w.write_all(&bytes))?;
        }
        let md = markdown(self);
        write_atomic(&out.join("leaderboard.md"), |w| w.write_all(md.as_bytes()))
    }
}
