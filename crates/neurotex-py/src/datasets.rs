//! `neurotex datasets` and `neurotex benchmark` called from Python: the same recipes, cache
//! and leaderboard as the command line (`neurotex.datasets`, `neurotex.benchmark`).

use std::path::PathBuf;

use neurotex::datasets::{self, DatasetsCommand};
use neurotex::workflows::benchmark::{BenchmarkOptions, Share};
use pyo3::prelude::*;

use crate::errors::guarded;
use crate::model::Said;

/// Runs one `neurotex datasets` command; returns the lines it prints (what it says on its
/// way goes to Python's log).
fn run(py: Python<'_>, command: DatasetsCommand) -> PyResult<Vec<String>> {
    let said = Said::default();
    let on = |p: neurotex::progress::Progress| said.hear(p);
    crate::interrupt::watched(py, || guarded(|| command.run(&on)))
}

/// The built-in recipes as dicts (name, title, citation, licence, protocols, published,
/// and the imported folder when fetched into `cache`).
#[pyfunction]
#[pyo3(signature = (cache=None))]
fn datasets_list(py: Python<'_>, cache: Option<PathBuf>) -> PyResult<Vec<Py<PyAny>>> {
    let root = guarded(|| datasets::cache_root(cache.as_deref()))?;
    datasets::built_in()
        .iter()
        .map(|r| {
            let fetched = datasets::fetched(&root, r).map(|p| p.display().to_string());
            let value = serde_json::json!({"recipe": r, "fetched": fetched});
            crate::convert::to_object(py, &value)
        })
        .collect()
}

/// The recipe `name_or_path`, checked, as a dict.
#[pyfunction]
fn datasets_check(py: Python<'_>, name_or_path: &str) -> PyResult<Py<PyAny>> {
    let recipe = guarded(|| datasets::resolve(name_or_path))?;
    crate::convert::to_object(py, &recipe)
}

/// Fetches a dataset into the cache; its folder.
#[pyfunction]
#[pyo3(signature = (name, source=None, cache=None))]
fn datasets_fetch(
    py: Python<'_>,
    name: String,
    source: Option<PathBuf>,
    cache: Option<PathBuf>,
) -> PyResult<String> {
    let command = DatasetsCommand::Fetch {
        name,
        from: source,
        cache,
    };
    Ok(run(py, command)?.concat())
}

/// The imported folder of a fetched dataset.
#[pyfunction]
#[pyo3(signature = (name, cache=None))]
fn datasets_path(py: Python<'_>, name: String, cache: Option<PathBuf>) -> PyResult<String> {
    Ok(run(py, DatasetsCommand::Path { name, cache })?.concat())
}

/// `neurotex benchmark`'s options, from the Python arguments.
#[allow(clippy::too_many_arguments)]
fn options(
    datasets: Vec<String>,
    out: PathBuf,
    cache: Option<PathBuf>,
    source: Option<PathBuf>,
    protocols: Vec<String>,
    snn: bool,
    (folds, repeats, seed): (usize, usize, u64),
) -> BenchmarkOptions {
    BenchmarkOptions {
        datasets,
        out,
        cache,
        from: source,
        protocols,
        snn,
        folds,
        repeats,
        seed,
    }
}

/// Runs `neurotex benchmark`; the leaderboard (what it says on its way goes to Python's log).
#[pyfunction]
#[pyo3(signature = (datasets, out, cache=None, source=None, protocols=Vec::new(), snn=false, folds=5, repeats=1, seed=0))]
#[allow(clippy::too_many_arguments)]
fn benchmark(
    py: Python<'_>,
    datasets: Vec<String>,
    out: PathBuf,
    cache: Option<PathBuf>,
    source: Option<PathBuf>,
    protocols: Vec<String>,
    snn: bool,
    folds: usize,
    repeats: usize,
    seed: u64,
) -> PyResult<Py<PyAny>> {
    let options = options(
        datasets,
        out,
        cache,
        source,
        protocols,
        snn,
        (folds, repeats, seed),
    );
    let said = Said::default();
    let on = |p: neurotex::progress::Progress| said.hear(p);
    let board = crate::interrupt::watched(py, || guarded(|| options.run(&on)))?;
    crate::convert::to_object(py, &board)
}

/// A share as Python holds it: dataset, recipe, protocol, encoding and method (`None` for
/// every method of the encoding).
type ShareTuple = (String, String, String, String, Option<String>);

/// The shares of a benchmark's work that separate tasks can compute side by side, as
/// `(dataset, recipe, protocol, encoding, method)`; fetches every dataset first.
#[pyfunction]
#[pyo3(signature = (datasets, out, cache=None, source=None, protocols=Vec::new(), snn=false, folds=5, repeats=1, seed=0))]
#[allow(clippy::too_many_arguments)]
fn benchmark_shares(
    py: Python<'_>,
    datasets: Vec<String>,
    out: PathBuf,
    cache: Option<PathBuf>,
    source: Option<PathBuf>,
    protocols: Vec<String>,
    snn: bool,
    folds: usize,
    repeats: usize,
    seed: u64,
) -> PyResult<Vec<ShareTuple>> {
    let options = options(
        datasets,
        out,
        cache,
        source,
        protocols,
        snn,
        (folds, repeats, seed),
    );
    let shares = py.detach(|| guarded(|| options.shares(&neurotex::progress::silent)))?;
    Ok(shares
        .into_iter()
        .map(|s| (s.dataset, s.recipe, s.protocol, s.encoding, s.method))
        .collect())
}

/// Computes and keeps one share's pieces in `out` (a share of [`benchmark_shares`]).
#[pyfunction]
#[pyo3(signature = (share, out, cache=None, snn=false, folds=5, repeats=1, seed=0))]
#[allow(clippy::too_many_arguments)]
fn benchmark_share(
    py: Python<'_>,
    share: ShareTuple,
    out: PathBuf,
    cache: Option<PathBuf>,
    snn: bool,
    folds: usize,
    repeats: usize,
    seed: u64,
) -> PyResult<()> {
    let (dataset, recipe, protocol, encoding, method) = share;
    let share = Share {
        dataset,
        recipe: recipe.clone(),
        protocol,
        encoding,
        method,
    };
    let options = options(
        vec![recipe],
        out,
        cache,
        None,
        Vec::new(),
        snn,
        (folds, repeats, seed),
    );
    py.detach(|| guarded(|| options.run_share(&share, &neurotex::progress::silent)))
}

/// Registers the functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(datasets_list, m)?)?;
    m.add_function(wrap_pyfunction!(datasets_check, m)?)?;
    m.add_function(wrap_pyfunction!(datasets_fetch, m)?)?;
    m.add_function(wrap_pyfunction!(datasets_path, m)?)?;
    m.add_function(wrap_pyfunction!(benchmark, m)?)?;
    m.add_function(wrap_pyfunction!(benchmark_shares, m)?)?;
    m.add_function(wrap_pyfunction!(benchmark_share, m)?)
}
