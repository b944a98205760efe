//! Records the git commit neurotex is built from, when it is built from a checkout, so
//! results and models can say which code made them (`NEUROTEX_GIT_COMMIT`, empty otherwise).

use std::path::Path;
use std::process::Command;

/// `git ARGS`'s output, trimmed, when git runs and succeeds.
fn git(args: &[&str]) -> Option<String> {
    Command::new("git")
        .args(args)
        .output()
        .ok()
        .filter(|o| o.status.success())
        .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
}

fn main() {
    let commit = git(&["rev-parse", "--short=12", "HEAD"]).unwrap_or_default();
    println!("cargo:rustc-env=NEUROTEX_GIT_COMMIT={commit}");
    // A new commit changes HEAD (a detached checkout) or the branch's ref. Git says where
    // they are: in a linked worktree `.git` is a file and HEAD lives under the main
    // checkout's `.git/worktrees/`, the refs in its common folder. A path that does not
    // exist would make cargo rerun this script, and rebuild the crate, on every build.
    println!("cargo:rerun-if-changed=build.rs");
    let mut watched = vec![git(&["rev-parse", "--git-path", "HEAD"])];
    if let Some(branch) = git(&["rev-parse", "--symbolic-full-name", "HEAD"]) {
        if branch.starts_with("refs/") {
            watched.push(git(&["rev-parse", "--git-path", &branch]));
            watched.push(git(&["rev-parse", "--git-path", "packed-refs"]));
        }
    }
    for path in watched.into_iter().flatten() {
        if Path::new(&path).exists() {
            println!("cargo:rerun-if-changed={path}");
        }
    }
}
