//! `neurotex datasets` and `neurotex benchmark`: public datasets by recipe (fetched,
//! checked, imported once) and their leaderboard (docs/benchmark.md).

use anyhow::Result;
use neurotex::workflows::benchmark::BenchmarkOptions;
use neurotex::workflows::datasets::DatasetsCommand;

use crate::output::Shown;

/// Runs `neurotex datasets`.
pub fn run(command: DatasetsCommand) -> Result<()> {
    let shown = Shown::new("starting");
    let lines = command.run(&shown.callback());
    shown.finish();
    lines?.iter().for_each(|line| println!("{line}"));
    Ok(())
}

/// Runs `neurotex benchmark`.
pub fn benchmark(options: BenchmarkOptions) -> Result<()> {
    let shown = Shown::new("starting");
    let board = options.run(&shown.callback());
    shown.finish();
    board?.summary().iter().for_each(|line| println!("{line}"));
    let path = options.out.join("leaderboard.md");
    println!("leaderboard in {}", path.display());
    Ok(())
}
