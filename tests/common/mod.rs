//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

use verdem::case::Case;
use verdem::engine::{self, Overrides};
use verdem::scene;
use verdem::sim::Engine;

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A file of the benchmark's shared data (`../shared/data/...`); the tests need it and say so.
pub fn shared(rel: &str) -> PathBuf {
    let p = root().join("../shared/data").join(rel);
    assert!(
        p.exists(),
        "{} is missing: the tests need the benchmark's shared data beside the repository",
        p.display()
    );
    p
}

/// The quick shear case.
pub fn quick_case() -> Case {
    Case::load(&root().join("cases/shear_flow_quick.toml")).expect("case loads")
}

/// An engine for `case` starting from `init` (or the generated scene), with overrides.
pub fn engine(case: &Case, init: Option<&Path>, o: Overrides) -> Box<dyn Engine> {
    let s = scene::build(case, init).expect("scene builds");
    engine::build(case, s, &o)
}

/// State hash after `steps` steps.
pub fn hash_after(engine: &mut dyn Engine, steps: u64) -> String {
    engine.advance(steps);
    verdem::hash::state_hash(&engine.core().snapshot())
}
