//! Writes the seed corpus, `fuzz/corpus/TARGET/seed-N`, from `harness::seeds()`. Run from
//! the repository root: `cargo +nightly run --manifest-path fuzz/Cargo.toml --bin seeds`.

use std::path::Path;

fn main() -> std::io::Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("corpus");
    for (i, (target, bytes)) in neurotex_fuzz::harness::seeds().into_iter().enumerate() {
        let dir = root.join(target);
        std::fs::create_dir_all(&dir)?;
        std::fs::write(dir.join(format!("seed-{i}")), bytes)?;
    }
    println!("seeds written to {}", root.display());
    Ok(())
}
