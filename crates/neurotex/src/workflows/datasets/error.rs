//! The rules a dataset recipe breaks, each naming its key.

use thiserror::Error;

/// A broken rule of a recipe (docs/benchmark.md); the message names the key.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum RecipeError {
    /// `name` is not lowercase letters, digits and `-`, starting with a letter.
    #[error("name = {0:?}: a name is lowercase letters, digits and -, starting with a letter")]
    Name(String),
    /// No `[[source]]`.
    #[error("no [[source]]: a recipe needs at least one")]
    NoSources,
    /// A source breaks a rule.
    #[error("[[source]] {index} ({url}): {rule}")]
    Source {
        /// 1-based position among the sources.
        index: usize,
        /// Its URL.
        url: String,
        /// The rule.
        rule: SourceRule,
    },
    /// An import option does not parse, or a path leaves the fetched files.
    #[error("[import]: {key} = {value:?}: {reason}")]
    Import {
        /// The key.
        key: String,
        /// Its value.
        value: String,
        /// Why it does not parse.
        reason: String,
    },
    /// No `[[protocol]]`.
    #[error("no [[protocol]]: a recipe needs at least one")]
    NoProtocols,
    /// A protocol id is not a slug, or is taken.
    #[error("[[protocol]] id = {0:?}: ids are distinct, lowercase letters, digits and -")]
    ProtocolId(String),
    /// A protocol gives both or neither of `per` and `hold-out`.
    #[error("[[protocol]] {0}: give exactly one of per and hold-out")]
    ProtocolKind(String),
    /// A protocol's column has fewer than 2 values in `[conditions]`.
    #[error("[[protocol]] {id}: column {column} needs its values (at least 2) in [conditions]")]
    ProtocolConditions {
        /// The protocol's id.
        id: String,
        /// Its column.
        column: String,
    },
    /// A published result is beside no protocol of the recipe.
    #[error("[[published]] {citation}: beside = {beside:?} is not a protocol id of the recipe")]
    PublishedBeside {
        /// Who published it.
        citation: String,
        /// The id given.
        beside: String,
    },
    /// A published accuracy outside 0..1.
    #[error("[[published]] {citation}: accuracy = {accuracy} is not in 0..1")]
    PublishedAccuracy {
        /// Who published it.
        citation: String,
        /// The accuracy given.
        accuracy: f64,
    },
}

/// The rules of one source.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum SourceRule {
    /// The URL is not http(s).
    #[error("url must start with https:// or http://")]
    Url,
    /// A checksum is not 64 lowercase hex digits.
    #[error("{key} = {value:?} is not 64 lowercase hex digits")]
    Hex {
        /// `sha256` or `tree-sha256`.
        key: &'static str,
        /// The value given.
        value: String,
    },
    /// A `git-archive` source without `tree-sha256`.
    #[error("a git-archive source needs tree-sha256 (its archive's bytes may change)")]
    TreeDigest,
    /// A `zip`, `tar.gz` or `file` source without `sha256` and `size`.
    #[error("missing checksum: sha256 and size are required")]
    Checksum,
    /// A `file` source with a `folder`.
    #[error("a file source has no folder")]
    FileFolder,
    /// Two sources saved under the same file name.
    #[error("another source's URL ends in the same file name, {0}; each is saved by that name")]
    SameName(String),
}
