//! Public tactile datasets by recipe: a small TOML file per dataset gives its sources with
//! their checksums, the import that turns them into a dataset folder, the conditions its
//! protocols use and the results published on it (docs/benchmark.md). The recipes of the
//! datasets neurotex knows are built in; a user's own is read from its file.

mod digest;
mod download;
mod error;
pub mod fetch;
pub mod recipe;
mod unpack;

use std::path::{Path, PathBuf};

use super::OnProgress;
use crate::error::DataError;

pub use digest::{file_digest, tree_digest};
pub use error::{RecipeError, SourceRule};
pub use fetch::{cache_root, entry, fetch, fetched};
pub use recipe::{ProtocolSpec, Published, Recipe, Source, SourceKind};

use crate::Result;

/// The built-in recipes: (name, text).
const BUILT_IN: &[(&str, &str)] = &[(
    "fabricslide",
    include_str!("../../../recipes/fabricslide.toml"),
)];

/// The built-in recipes, parsed.
///
/// # Panics
/// A built-in recipe that does not parse (a test keeps them parsing).
pub fn built_in() -> Vec<Recipe> {
    BUILT_IN
        .iter()
        .map(|(name, text)| {
            Recipe::parse(text, Path::new(&format!("{name}.toml")))
                .unwrap_or_else(|e| panic!("built-in recipe {name}: {e}"))
        })
        .collect()
}

/// The recipe named `name_or_path`: a built-in one by name, or the recipe file at that path
/// (a name ending in `.toml` or holding a `/`).
///
/// # Errors
/// No built-in recipe of that name and no such file, or a file that is not a valid recipe.
pub fn resolve(name_or_path: &str) -> Result<Recipe> {
    let looks_like_path = name_or_path.ends_with(".toml") || name_or_path.contains('/');
    if looks_like_path || Path::new(name_or_path).is_file() {
        return Recipe::read(Path::new(name_or_path));
    }
    match built_in().into_iter().find(|r| r.name == name_or_path) {
        Some(recipe) => Ok(recipe),
        None => {
            let known: Vec<String> = built_in().into_iter().map(|r| r.name).collect();
            let why = format!(
                "no built-in recipe of this name (known: {}); give a recipe file's path for another dataset",
                known.join(", ")
            );
            Err(DataError::invalid(name_or_path, why).into())
        }
    }
}

/// `neurotex datasets`: the public datasets neurotex has recipes for.
#[derive(Debug, Clone)]
#[cfg_attr(feature = "cli", derive(clap::Subcommand))]
pub enum DatasetsCommand {
    /// The built-in recipes: name, whether each is in the cache, licence and title.
    List {
        /// The cache (default: $NEUROTEX_CACHE, else $XDG_CACHE_HOME/neurotex, else
        /// ~/.cache/neurotex).
        #[cfg_attr(feature = "cli", arg(long))]
        cache: Option<PathBuf>,
    },
    /// Check a recipe (a built-in name or a recipe file) without fetching anything.
    Check {
        /// The recipe.
        recipe: String,
    },
    /// Fetch a dataset into the cache: download its sources (an interrupted download
    /// resumes on the next run) or take them from a local copy, verify every checksum,
    /// import it once, and print the dataset folder.
    Fetch {
        /// A built-in recipe's name or a recipe file.
        name: String,
        /// A local copy of the sources instead of downloading them: a folder of the
        /// downloaded files (or the unpacked folder a recipe's tree digest checks), or a
        /// one-source recipe's file itself.
        #[cfg_attr(feature = "cli", arg(long))]
        from: Option<PathBuf>,
        /// The cache (default as for `list`).
        #[cfg_attr(feature = "cli", arg(long))]
        cache: Option<PathBuf>,
    },
    /// Print a fetched dataset's folder (for `--dataset` of the other commands).
    Path {
        /// A built-in recipe's name or a recipe file.
        name: String,
        /// The cache (default as for `list`).
        #[cfg_attr(feature = "cli", arg(long))]
        cache: Option<PathBuf>,
    },
    /// Print a file's SHA-256 and size, or a folder's tree digest: the checksums a
    /// recipe's source needs.
    Digest {
        /// The file or folder.
        path: PathBuf,
    },
}

impl DatasetsCommand {
    /// Runs the command and returns the lines it prints.
    ///
    /// # Errors
    /// A recipe that is not valid, a dataset that cannot be fetched or is not in the cache
    /// (`path`), a file that cannot be read.
    pub fn run(&self, on: OnProgress) -> Result<Vec<String>> {
        match self {
            DatasetsCommand::List { cache } => {
                let root = cache_root(cache.as_deref())?;
                Ok(built_in()
                    .iter()
                    .map(|r| {
                        let state = fetched(&root, r).map_or("not fetched", |_| "fetched");
                        format!("{:<14} {state:<12} {:<5} {}", r.name, r.licence, r.title)
                    })
                    .collect())
            }
            DatasetsCommand::Check { recipe } => {
                let r = resolve(recipe)?;
                Ok(vec![format!(
                    "{recipe}: a valid recipe for {} ({} source(s), {} protocol(s))",
                    r.name,
                    r.sources.len(),
                    r.protocols.len()
                )])
            }
            DatasetsCommand::Fetch { name, from, cache } => {
                let root = cache_root(cache.as_deref())?;
                let dir = fetch(&resolve(name)?, &root, from.as_deref(), on)?;
                Ok(vec![dir.display().to_string()])
            }
            DatasetsCommand::Path { name, cache } => {
                let root = cache_root(cache.as_deref())?;
                match fetched(&root, &resolve(name)?) {
                    Some(dir) => Ok(vec![dir.display().to_string()]),
                    None => {
                        let why = format!("{name} is not in this cache: `neurotex datasets fetch {name}` downloads it (or takes a local copy with --from)");
                        Err(DataError::invalid(&root, why).into())
                    }
                }
            }
            DatasetsCommand::Digest { path } if path.is_dir() => {
                Ok(vec![format!("tree-sha256 = \"{}\"", tree_digest(path)?)])
            }
            DatasetsCommand::Digest { path } => {
                let size = std::fs::metadata(path)
                    .map_err(|reason| DataError::Io {
                        path: path.clone(),
                        reason,
                    })?
                    .len();
                Ok(vec![
                    format!("sha256 = \"{}\"", file_digest(path)?),
                    format!("size = {size}"),
                ])
            }
        }
    }
}
