//! A dataset recipe: where a public dataset's files come from (with their checksums), how
//! they are imported into a dataset folder, the conditions its protocols use and the
//! results published on it. The format is documented in docs/benchmark.md.

use std::collections::BTreeMap;
use std::fmt::Display;
use std::path::{Path, PathBuf};
use std::str::FromStr;

use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};

use super::error::{RecipeError, SourceRule};
use crate::error::DataError;
use crate::workflows::import::{ImportCsvOptions, ImportStackedOptions};
use crate::workflows::{CsvOptions, LogOptions};
use crate::Result;

/// One public dataset's recipe.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
pub struct Recipe {
    /// The name commands take: lowercase letters, digits and `-`.
    pub name: String,
    /// A one-line description.
    pub title: String,
    /// The publication to cite for the data.
    pub citation: String,
    /// The data's licence.
    pub licence: String,
    /// Where the data is described.
    #[serde(default)]
    pub homepage: Option<String>,
    /// The files, each with its checksum.
    #[serde(rename = "source")]
    pub sources: Vec<Source>,
    /// How the files become a dataset folder.
    pub import: ImportSpec,
    /// For each manifest column the protocols use, the values the data has.
    pub conditions: BTreeMap<String, Vec<String>>,
    /// The protocols the benchmark runs, in order.
    #[serde(rename = "protocol")]
    pub protocols: Vec<ProtocolSpec>,
    /// Results published on the data.
    #[serde(default)]
    pub published: Vec<Published>,
}

/// One file of a dataset: an archive, a raw file, or a folder inside a repository's archive.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
pub struct Source {
    /// Where it is downloaded from.
    pub url: String,
    /// What it is.
    pub kind: SourceKind,
    /// SHA-256 of the downloaded file (hex): required for `zip`, `tar.gz` and `file`.
    #[serde(default)]
    pub sha256: Option<String>,
    /// Size of the downloaded file in bytes: required with `sha256`.
    #[serde(default)]
    pub size: Option<u64>,
    /// The folder inside the archive whose files are used (default: all of it).
    #[serde(default)]
    pub folder: Option<String>,
    /// The tree digest of the folder used (docs/benchmark.md): required for
    /// `git-archive`, whose archive bytes a host may change between downloads.
    #[serde(default)]
    pub tree_sha256: Option<String>,
    /// The most bytes an archive may unpack to (default: a hundred times its size, at
    /// least 1 GiB); unpacking stops with an error past it. Left out of the digest of the
    /// sources when absent, so that recipes without it keep their cache entries.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unpacked_at_most: Option<u64>,
}

/// The kinds of source.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum SourceKind {
    /// A zip archive.
    #[serde(rename = "zip")]
    Zip,
    /// A gzip-compressed tar archive.
    #[serde(rename = "tar.gz")]
    TarGz,
    /// One file, used as it is.
    #[serde(rename = "file")]
    File,
    /// A repository's archive (a zip), checked by the tree digest of its `folder`.
    #[serde(rename = "git-archive")]
    GitArchive,
}

/// The import that turns the fetched files into a dataset folder: `neurotex import csv`'s or
/// `import stacked`'s options, written once, with the flags' names as keys.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum ImportSpec {
    /// Per-trial CSV logs.
    Csv(CsvSpec),
    /// A stacked array with one label (and optionally one speed) per sample.
    Stacked(StackedSpec),
}

/// `import csv`'s options in a recipe.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
pub struct CsvSpec {
    /// Files or folders under the fetched files (default: all of them).
    #[serde(default)]
    pub inputs: Vec<String>,
    /// `--name-pattern`.
    #[serde(default)]
    pub name_pattern: Option<String>,
    /// `--no-header`.
    #[serde(default)]
    pub no_header: bool,
    /// `--delimiter`.
    #[serde(default)]
    pub delimiter: Option<String>,
    /// `--time-column`.
    #[serde(default)]
    pub time_column: Option<String>,
    /// `--time-unit`.
    #[serde(default)]
    pub time_unit: Option<String>,
    /// `--channels`.
    #[serde(default)]
    pub channels: Option<String>,
    /// `--duplicate-stamps`.
    #[serde(default)]
    pub duplicate_stamps: Option<String>,
    /// `--max-gap-s`.
    #[serde(default)]
    pub max_gap_s: Option<f64>,
    /// `--grid`.
    #[serde(default)]
    pub grid: Option<String>,
    /// `--channel-map`.
    #[serde(default)]
    pub channel_map: Option<String>,
    /// `--drop-channels`.
    #[serde(default)]
    pub drop_channels: Option<String>,
    /// `--fs`.
    #[serde(default)]
    pub fs: Option<f64>,
    /// `--baseline`.
    #[serde(default)]
    pub baseline: Option<String>,
}

/// `import stacked`'s options in a recipe.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
pub struct StackedSpec {
    /// `--data`, under the fetched files.
    pub data: String,
    /// `--labels`.
    pub labels: String,
    /// `--axes`.
    pub axes: String,
    /// `--fs`.
    pub fs: f64,
    /// `--speeds`.
    #[serde(default)]
    pub speeds: Option<String>,
    /// `--grid`.
    #[serde(default)]
    pub grid: Option<String>,
}

/// An import ready to run on a folder of fetched files.
#[derive(Debug, Clone)]
pub enum Import {
    /// `import csv`.
    Csv(ImportCsvOptions),
    /// `import stacked`.
    Stacked(ImportStackedOptions),
}

/// One protocol: cross-validation within each value of a column, or each value held out.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
pub struct ProtocolSpec {
    /// A short name for files and links: lowercase letters, digits and `-`.
    pub id: String,
    /// Cross-validate within each value of this column.
    #[serde(default)]
    pub per: Option<String>,
    /// Hold out each value of this column in turn.
    #[serde(default)]
    pub hold_out: Option<String>,
}

impl ProtocolSpec {
    /// The column the protocol splits by.
    pub fn column(&self) -> &str {
        self.per
            .as_deref()
            .or(self.hold_out.as_deref())
            .unwrap_or("")
    }

    /// The protocol in words.
    pub fn describe(&self) -> String {
        match (&self.per, &self.hold_out) {
            (Some(c), _) => format!("cross-validation within each {c}"),
            (_, Some(c)) => format!("each {c} held out (trained on the others)"),
            _ => String::new(),
        }
    }
}

/// A published result on the dataset.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, rename_all = "kebab-case")]
pub struct Published {
    /// Accuracy, 0..1.
    pub accuracy: f64,
    /// The method and protocol as the publication states them.
    pub protocol: String,
    /// Who published it.
    pub citation: String,
    /// The recipe protocol (`id`) it is shown beside.
    pub beside: String,
    /// Whether its protocol is the same as that one (folds, recordings, conditions).
    pub same_protocol: bool,
}

/// Whether `name` is lowercase letters, digits and `-`, starting with a letter.
fn is_slug(name: &str) -> bool {
    name.starts_with(|c: char| c.is_ascii_lowercase())
        && name
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '-')
}

/// Whether `hex` is a SHA-256 in lowercase hex.
fn is_sha256(hex: &str) -> bool {
    hex.len() == 64 && hex.chars().all(|c| matches!(c, '0'..='9' | 'a'..='f'))
}

impl Recipe {
    /// Reads and checks the recipe file `path`.
    ///
    /// # Errors
    /// The file cannot be read, is not TOML, has a key the format does not know or breaks a
    /// rule ([`Recipe::check`]); the message names the file and the key.
    pub fn read(path: &Path) -> Result<Recipe> {
        let text = std::fs::read_to_string(path).map_err(|reason| DataError::Io {
            path: path.to_path_buf(),
            reason,
        })?;
        Recipe::parse(&text, path)
    }

    /// Parses and checks a recipe's text; `path` names it in errors.
    ///
    /// # Errors
    /// As [`Recipe::read`].
    pub fn parse(text: &str, path: &Path) -> Result<Recipe> {
        let recipe: Recipe =
            toml::from_str(text).map_err(|e| DataError::invalid(path, e.to_string()))?;
        recipe
            .check()
            .map_err(|e| DataError::invalid(path, e.to_string()))?;
        Ok(recipe)
    }

    /// The rules a recipe keeps, each broken one said with its key: a name of lowercase
    /// letters, digits and `-`; at least one source, each with its checksums; an import whose
    /// options parse; protocols on columns the conditions list, with distinct ids; published
    /// results beside a protocol of the recipe, with accuracies in 0..1.
    ///
    /// # Errors
    /// The first rule broken, naming the key.
    pub fn check(&self) -> std::result::Result<(), RecipeError> {
        if !is_slug(&self.name) {
            return Err(RecipeError::Name(self.name.clone()));
        }
        if self.sources.is_empty() {
            return Err(RecipeError::NoSources);
        }
        let mut names: Vec<&str> = Vec::new();
        for (i, s) in self.sources.iter().enumerate() {
            let name = s.url.split(['?', '#']).next().unwrap_or_default();
            let name = name.rsplit('/').next().unwrap_or_default();
            let rule = match check_source(s) {
                Err(rule) => Some(rule),
                Ok(()) if names.contains(&name) => Some(SourceRule::SameName(name.into())),
                Ok(()) => None,
            };
            if let Some(rule) = rule {
                let url = s.url.clone();
                return Err(RecipeError::Source {
                    index: i + 1,
                    url,
                    rule,
                });
            }
            names.push(name);
        }
        self.import_in(Path::new("."))?;
        self.check_protocols()
    }

    /// The protocols' and the published results' rules of [`Recipe::check`].
    fn check_protocols(&self) -> std::result::Result<(), RecipeError> {
        if self.protocols.is_empty() {
            return Err(RecipeError::NoProtocols);
        }
        let mut ids: Vec<&str> = Vec::new();
        for p in &self.protocols {
            if !is_slug(&p.id) || ids.contains(&p.id.as_str()) {
                return Err(RecipeError::ProtocolId(p.id.clone()));
            }
            ids.push(&p.id);
            if p.per.is_some() == p.hold_out.is_some() {
                return Err(RecipeError::ProtocolKind(p.id.clone()));
            }
            if self.conditions.get(p.column()).is_none_or(|v| v.len() < 2) {
                let (id, column) = (p.id.clone(), p.column().to_string());
                return Err(RecipeError::ProtocolConditions { id, column });
            }
        }
        for p in &self.published {
            let citation = p.citation.clone();
            if !ids.contains(&p.beside.as_str()) {
                let beside = p.beside.clone();
                return Err(RecipeError::PublishedBeside { citation, beside });
            }
            if !(0.0..=1.0).contains(&p.accuracy) {
                let accuracy = p.accuracy;
                return Err(RecipeError::PublishedAccuracy { citation, accuracy });
            }
        }
        Ok(())
    }

    /// The import's options with its paths under `files` (the fetched files' folder).
    ///
    /// # Errors
    /// An option that does not parse, named by its key.
    pub fn import_in(&self, files: &Path) -> std::result::Result<Import, RecipeError> {
        match &self.import {
            ImportSpec::Csv(spec) => spec.options(files).map(Import::Csv),
            ImportSpec::Stacked(s) => Ok(Import::Stacked(ImportStackedOptions {
                data: under(files, &s.data)?,
                labels: under(files, &s.labels)?,
                axes: parse("axes", &s.axes)?,
                fs: parse("fs", &s.fs.to_string())?,
                speeds: s.speeds.as_deref().map(|p| under(files, p)).transpose()?,
                grid: opt("grid", &s.grid)?,
            })),
        }
    }

    /// A digest of what decides the imported dataset (sources and import): a fetched copy is
    /// reused only under the recipe that made it.
    pub fn import_digest(&self) -> String {
        let key = serde_json::to_string(&(&self.sources, &self.import)).unwrap_or_default();
        hex(&Sha256::digest(key.as_bytes()))
    }
}

impl CsvSpec {
    /// `import csv`'s options, its inputs under `files`.
    fn options(&self, files: &Path) -> std::result::Result<ImportCsvOptions, RecipeError> {
        let inputs = match self.inputs.is_empty() {
            true => vec![files.to_path_buf()],
            false => (self.inputs.iter())
                .map(|p| under(files, p))
                .collect::<std::result::Result<_, _>>()?,
        };
        let csv = CsvOptions {
            no_header: self.no_header,
            delimiter: opt("delimiter", &self.delimiter)?,
            time_column: opt("time-column", &self.time_column)?,
            time_unit: opt("time-unit", &self.time_unit)?,
            channels: opt("channels", &self.channels)?,
            duplicate_stamps: opt("duplicate-stamps", &self.duplicate_stamps)?,
            max_gap_s: self.max_gap_s,
        };
        let logs = LogOptions {
            name_pattern: opt("name-pattern", &self.name_pattern)?,
            csv,
            grid: opt("grid", &self.grid)?,
            channel_map: opt("channel-map", &self.channel_map)?,
            drop_channels: opt("drop-channels", &self.drop_channels)?,
            fs: opt("fs", &self.fs.map(|v| v.to_string()))?,
        };
        Ok(ImportCsvOptions {
            inputs,
            logs,
            baseline: opt("baseline", &self.baseline)?,
            skip_bad: false,
        })
    }
}

/// `p` under the fetched files' folder `files`: relative, without `..`.
fn under(files: &Path, p: &str) -> std::result::Result<PathBuf, RecipeError> {
    let rel = Path::new(p);
    if rel.is_absolute() || rel.components().any(|c| c.as_os_str() == "..") {
        return Err(RecipeError::Import {
            key: "a path".into(),
            value: p.into(),
            reason: "paths are relative to the fetched files, without ..".into(),
        });
    }
    Ok(files.join(rel))
}

/// A source's checksums as its kind needs them.
fn check_source(s: &Source) -> std::result::Result<(), SourceRule> {
    if !(s.url.starts_with("https://") || s.url.starts_with("http://")) {
        return Err(SourceRule::Url);
    }
    for (key, value) in [("sha256", &s.sha256), ("tree-sha256", &s.tree_sha256)] {
        if let Some(h) = value.as_deref().filter(|h| !is_sha256(h)) {
            return Err(SourceRule::Hex {
                key,
                value: h.into(),
            });
        }
    }
    match s.kind {
        SourceKind::GitArchive if s.tree_sha256.is_none() => Err(SourceRule::TreeDigest),
        SourceKind::GitArchive => Ok(()),
        _ if s.sha256.is_none() || s.size.is_none() => Err(SourceRule::Checksum),
        SourceKind::File if s.folder.is_some() => Err(SourceRule::FileFolder),
        _ => Ok(()),
    }
}

/// `text` parsed as the flag `key` parses it.
fn parse<T: FromStr>(key: &str, text: &str) -> std::result::Result<T, RecipeError>
where
    T::Err: Display,
{
    text.parse().map_err(|e: T::Err| RecipeError::Import {
        key: key.into(),
        value: text.into(),
        reason: e.to_string(),
    })
}

/// An optional option parsed as [`parse`] does.
fn opt<T: FromStr>(key: &str, text: &Option<String>) -> std::result::Result<Option<T>, RecipeError>
where
    T::Err: Display,
{
    text.as_deref().map(|t| parse(key, t)).transpose()
}

/// Lowercase hex of `bytes`.
pub(crate) fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}
