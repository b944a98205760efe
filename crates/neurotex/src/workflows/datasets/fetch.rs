//! Fetching a recipe's dataset into the cache: every source downloaded or found in a local
//! copy, its checksum verified,
//! unpacked (no entry outside its folder), imported once, and the whole entry renamed into
//! place only when all of it succeeded, so that a failure leaves the cache as it was.

use std::path::{Path, PathBuf};

use super::digest::{copy_tree, tree_digest};
use super::recipe::{Import, Recipe, Source, SourceKind};
use crate::error::DataError;
use crate::io::create_dir_atomic;
use crate::progress::Progress;
use crate::recording::Dataset;
use crate::workflows::OnProgress;
use crate::{Error, Result};

/// The cache folder: `dir` when given, else `$NEUROTEX_CACHE`, else
/// `$XDG_CACHE_HOME/neurotex`, else `~/.cache/neurotex`.
///
/// # Errors
/// None of them is set.
pub fn cache_root(dir: Option<&Path>) -> Result<PathBuf> {
    let var = |name: &str| std::env::var_os(name).filter(|v| !v.is_empty());
    if let Some(dir) = dir {
        return Ok(dir.to_path_buf());
    }
    if let Some(dir) = var("NEUROTEX_CACHE") {
        return Ok(PathBuf::from(dir));
    }
    if let Some(xdg) = var("XDG_CACHE_HOME") {
        return Ok(PathBuf::from(xdg).join("neurotex"));
    }
    match var("HOME") {
        Some(home) => Ok(PathBuf::from(home).join(".cache").join("neurotex")),
        None => Err(DataError::invalid(
            "~/.cache",
            "no cache folder: set NEUROTEX_CACHE or give --cache",
        )
        .into()),
    }
}

/// The cache entry of `recipe` under `root`: its name and a digest of its sources and
/// import, so that an edited recipe imports anew.
pub fn entry(root: &Path, recipe: &Recipe) -> PathBuf {
    root.join(format!("{}-{}", recipe.name, &recipe.import_digest()[..12]))
}

/// The imported dataset folder of `recipe` in the cache under `root`, when it was fetched.
pub fn fetched(root: &Path, recipe: &Recipe) -> Option<PathBuf> {
    let dir = entry(root, recipe);
    dir.join(FETCHED).is_file().then(|| dir.join("dataset"))
}

/// The record of a finished fetch in its cache entry.
const FETCHED: &str = "fetched.json";

/// Fetches `recipe`'s dataset into the cache under `root` from the local copy `from` (a
/// folder holding the sources' files by their URLs' names, or unpacked folders checked by
/// their tree digest; or, for a one-source recipe, the file itself), or without one by
/// downloading the sources, and returns the imported dataset folder. A dataset fetched
/// before is reused.
///
/// # Errors
/// A source that cannot be downloaded, a source not found in the copy, a checksum
/// that does not match, an archive entry outside its folder or a link, an import that fails,
/// or conditions the data does not have: each naming the recipe and the file.
pub fn fetch(recipe: &Recipe, root: &Path, from: Option<&Path>, on: OnProgress) -> Result<PathBuf> {
    if let Some(dataset) = fetched(root, recipe) {
        // The conditions are not part of the entry's name: an edited list is checked here.
        let opened = Dataset::open(&dataset)?;
        check_conditions(recipe, &opened, &dataset).map_err(|e| in_recipe(recipe, e))?;
        on(Progress::Say(&format!(
            "{}: fetched before, in {}",
            recipe.name,
            dataset.display()
        )));
        return Ok(dataset);
    }
    std::fs::create_dir_all(root).map_err(|e| DataError::write(root, e))?;
    let Some(from) = from else {
        // Downloaded into the cache, kept until the fetch succeeds (or resumed next time).
        let dir = root
            .join("downloads")
            .join(entry(root, recipe).file_name().unwrap_or_default());
        if let Err(e) = super::download::download_all(recipe, &dir, on) {
            // Folders left empty go; a partial download stays, to be resumed.
            let _ = std::fs::remove_dir(&dir);
            let _ = std::fs::remove_dir(root.join("downloads"));
            return Err(in_recipe(recipe, e));
        }
        let fetched = fetch_from(recipe, root, &dir, "downloaded", on);
        match &fetched {
            Ok(_) => std::fs::remove_dir_all(&dir).map_err(|e| DataError::write(&dir, e))?,
            Err(_) => {
                if super::download::drop_damaged(recipe, &dir) {
                    on(Progress::Advice("a download that was not the recipe's file was removed: the next run downloads it again"));
                }
                let _ = std::fs::remove_dir(&dir);
                let _ = std::fs::remove_dir(root.join("downloads"));
            }
        }
        return fetched;
    };
    fetch_from(recipe, root, from, &from.display().to_string(), on)
}

/// [`fetch`] from the files in `from`; `origin` says where they came from in the record.
fn fetch_from(
    recipe: &Recipe,
    root: &Path,
    from: &Path,
    origin: &str,
    on: OnProgress,
) -> Result<PathBuf> {
    let dir = entry(root, recipe);
    create_dir_atomic(&dir, |tmp| {
        // What the import says names the entry as it will be, not its hidden temporary.
        let (hidden, shown) = (tmp.display().to_string(), dir.display().to_string());
        let renamed = |p: Progress| match p {
            Progress::Say(s) => on(Progress::Say(&s.replace(&hidden, &shown))),
            Progress::Advice(s) => on(Progress::Advice(&s.replace(&hidden, &shown))),
            other => on(other),
        };
        fill(recipe, from, origin, tmp, &renamed)
    })
    .map_err(|e| in_recipe(recipe, e))?;
    Ok(dir.join("dataset"))
}

/// `error` named with the recipe it came from.
fn in_recipe(recipe: &Recipe, error: Error) -> Error {
    Error::InAnalysis {
        what: format!("recipe {}", recipe.name),
        source: Box::new(error),
    }
}

/// Fills the cache entry `tmp`: the sources into `files/`, their import into `dataset/`,
/// the conditions checked, the record written; `files/` is then removed (the dataset holds
/// what it needs).
fn fill(recipe: &Recipe, from: &Path, origin: &str, tmp: &Path, on: OnProgress) -> Result<()> {
    let files = tmp.join("files");
    std::fs::create_dir(&files).map_err(|e| DataError::write(&files, e))?;
    for (i, source) in recipe.sources.iter().enumerate() {
        on(Progress::Say(&format!(
            "{}: source {}",
            recipe.name, source.url
        )));
        let work = tmp.join(format!("unpack-{i}"));
        std::fs::create_dir(&work).map_err(|e| DataError::write(&work, e))?;
        let used = place(source, recipe.sources.len(), from, &work)?;
        move_into(&used, &files)?;
        std::fs::remove_dir_all(&work).map_err(|e| DataError::write(&work, e))?;
    }
    let dataset = tmp.join("dataset");
    let import = recipe
        .import_in(&files)
        .map_err(|e| DataError::invalid(&files, e.to_string()))?;
    match import {
        Import::Csv(options) => options.run(&dataset, on).map(|_| ())?,
        Import::Stacked(options) => options.run(&dataset).map(|_| ())?,
    }
    // Named by where the data came from: the cache entry being filled is rolled back.
    check_conditions(recipe, &Dataset::open(&dataset)?, from)?;
    std::fs::remove_dir_all(&files).map_err(|e| DataError::write(&files, e))?;
    let record = serde_json::json!({
        "recipe": recipe.name,
        "import_digest": recipe.import_digest(),
        "from": origin,
        "sources": recipe.sources,
    });
    let path = tmp.join(FETCHED);
    std::fs::write(&path, record.to_string()).map_err(|e| DataError::write(&path, e))?;
    Ok(())
}

/// Finds `source` in `from`, verifies it (its checksum, and its tree digest once, where its
/// files are) and puts its files under `work`; returns the folder of the files it
/// contributes (its `folder` inside an archive).
fn place(source: &Source, n_sources: usize, from: &Path, work: &Path) -> Result<PathBuf> {
    let name = super::download::file_name(source);
    let name = name.as_str();
    let file = if from.is_file() && n_sources == 1 {
        Some(from.to_path_buf())
    } else {
        Some(from.join(name)).filter(|p| p.is_file())
    };
    let Some(file) = file else {
        if source.tree_sha256.is_some() && from.is_dir() {
            // An unpacked copy: the folder itself, or the source's folder inside it.
            let inner = source.folder.as_deref().map(|f| from.join(f));
            let dir = inner.filter(|d| d.is_dir()).unwrap_or(from.to_path_buf());
            // Checked where it is, before anything of a wrong folder is copied.
            check_tree(source, &dir, from)?;
            copy_tree(&dir, work)?;
            return Ok(work.to_path_buf());
        }
        let why = format!("{name} (from {}) is not there", source.url);
        return Err(DataError::invalid(from, why).into());
    };
    if let (Some(size), Some(want)) = (source.size, &source.sha256) {
        let got_size = std::fs::metadata(&file)
            .map_err(|reason| DataError::Io {
                path: file.clone(),
                reason,
            })?
            .len();
        let got = super::digest::file_digest(&file)?;
        if got_size != size || &got != want {
            let why = format!("{got_size} bytes with SHA-256 {got}; the recipe says {size} bytes with {want}: a different or damaged file");
            return Err(DataError::invalid(&file, why).into());
        }
    }
    let budget = || -> Result<u64> {
        let bytes = std::fs::metadata(&file)
            .map_err(|reason| DataError::Io {
                path: file.clone(),
                reason,
            })?
            .len();
        Ok(source
            .unpacked_at_most
            .unwrap_or_else(|| super::unpack::default_budget(bytes)))
    };
    match source.kind {
        SourceKind::File => {
            let dest = work.join(name);
            std::fs::copy(&file, &dest).map_err(|e| DataError::write(&dest, e))?;
        }
        SourceKind::Zip | SourceKind::GitArchive => super::unpack::unzip(&file, work, budget()?)?,
        SourceKind::TarGz => super::unpack::untar_gz(&file, work, budget()?)?,
    }
    let used = match &source.folder {
        Some(folder) => work.join(folder),
        None => work.to_path_buf(),
    };
    if !used.is_dir() {
        let why = format!(
            "the archive has no folder {}",
            source.folder.as_deref().unwrap_or("")
        );
        return Err(DataError::invalid(&file, why).into());
    }
    check_tree(source, &used, from)?;
    Ok(used)
}

/// `dir` holds the files of `source`'s tree digest, when it has one; `from` (the copy
/// given) is named when it does not.
fn check_tree(source: &Source, dir: &Path, from: &Path) -> Result<()> {
    let Some(want) = &source.tree_sha256 else {
        return Ok(());
    };
    let got = tree_digest(dir)?;
    if &got == want {
        return Ok(());
    }
    let hint = match (&source.folder, source.url.rsplit('/').next()) {
        (Some(folder), Some(file)) => {
            format!(" (give the unpacked folder {folder} itself, or a folder holding {file})")
        }
        _ => String::new(),
    };
    let why = format!("tree digest {got}, the recipe's tree-sha256 is {want}: not the files the recipe describes{hint}");
    Err(DataError::invalid(from, why).into())
}

/// Moves what `from` holds into the folder `to`; two sources giving the same name is an
/// error, never one file replacing another.
fn move_into(from: &Path, to: &Path) -> Result<()> {
    let io = |reason| DataError::Io {
        path: from.to_path_buf(),
        reason,
    };
    for item in std::fs::read_dir(from).map_err(io)? {
        let item = item.map_err(io)?;
        let dest = to.join(item.file_name());
        if dest.symlink_metadata().is_ok() {
            let why = "two sources hold this name";
            return Err(DataError::invalid(&dest, why).into());
        }
        std::fs::rename(item.path(), &dest).map_err(|e| DataError::write(&dest, e))?;
    }
    Ok(())
}

/// Every value the recipe's `[conditions]` lists is in the dataset's manifest column; an
/// error names the data as `shown`.
fn check_conditions(recipe: &Recipe, dataset: &Dataset, shown: &Path) -> Result<()> {
    for (column, values) in &recipe.conditions {
        let have: Vec<String> = (dataset.entries.iter())
            .filter_map(|m| m.field(column))
            .collect();
        for value in values {
            if !have.iter().any(|h| h == value || same_number(h, value)) {
                let why = format!("[conditions] {column} = {value}: no recording has it (the recipe's conditions must be in the data)");
                return Err(DataError::invalid(shown, why).into());
            }
        }
    }
    Ok(())
}

/// Whether two values are the same number (`10` and `10.0`).
fn same_number(a: &str, b: &str) -> bool {
    matches!((a.parse::<f64>(), b.parse::<f64>()), (Ok(x), Ok(y)) if x == y)
}
