//! A toy peer: verdem itself as the other code, started as `verdem run` by a shell script, its
//! saves MercuryCG `.data`/`.fstat` files. It has no two-sphere collision run and no library
//! driven through a prescribed motion. `tests/recipe_peer.rs` adds it by the recipe of
//! `docs/extending.md`.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{bail, ensure, Context};

use super::{Frame, Installed, Launch, Peer, Run, Save};
use crate::case::Case;
use crate::contact::Tangential;
use crate::child::{self, OnParentDeath};
use crate::io::{atomic, mercury};
use crate::state::{Contact, Snapshot};

/// The toy.
pub struct Toy;

/// Its input script in its run folder.
const SCRIPT: &str = "in.toy.sh";

/// The folder of its saves in its run folder.
const SAVES: &str = "saves";

/// The save `kind` (`data` or `fstat`) with index `index` in `run`'s saves: the one file whose
/// name ends in `.KIND.NNNN` ([`mercury::save_path`]).
fn save_file(run: &Run, kind: &str, index: u64) -> anyhow::Result<PathBuf> {
    let dir = run.dir.join(SAVES);
    let tail = format!(".{kind}.{index:04}");
    let found: Vec<PathBuf> = std::fs::read_dir(&dir)
        .with_context(|| dir.display().to_string())?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.to_string_lossy().ends_with(&tail))
        .collect();
    match found.as_slice() {
        [one] => Ok(one.clone()),
        _ => bail!("{}: {} files end in {tail}", dir.display(), found.len()),
    }
}

impl Peer for Toy {
    fn name(&self) -> &'static str {
        "toy"
    }

    fn binary(&self) -> &'static str {
        "toy"
    }

    /// The verdem that runs it: always there.
    fn installed(&self) -> Installed {
        Installed::Yes(format!("verdem {}", env!("CARGO_PKG_VERSION")))
    }

    /// The convention of the case it is run on (`cases/shear_flow_quick.toml`): `verdem run`
    /// reads the case file as it is.
    fn convention(&self) -> Tangential {
        Tangential::Mercury
    }

    /// `STEM.data` ([`mercury::data_text`]).
    fn write_state(
        &self,
        s: &Snapshot,
        _density: f64,
        dir: &Path,
        stem: &str,
    ) -> anyhow::Result<String> {
        let name = format!("{stem}.data");
        atomic::write(&dir.join(&name), mercury::data_text(s).as_bytes())?;
        Ok(name)
    }

    /// `verdem run` of the case's file (its absolute path) from `state`, on `$NP` threads, a save every
    /// `dump_every` steps (without it, at the start and the end only).
    fn input_script(
        &self,
        case: &Case,
        state: &str,
        steps: u64,
        dump_every: Option<u64>,
    ) -> anyhow::Result<String> {
        let verdem = std::env::current_exe().context("the running verdem")?;
        let case_file = case
            .path
            .canonicalize()
            .with_context(|| format!("{}: the case file", case.path.display()))?;
        Ok(format!(
            "exec '{}' run '{}' --init '{state}' --steps {steps} --save-every {} --out {SAVES} \
             --threads \"$NP\" --quiet\n",
            verdem.display(),
            case_file.display(),
            dump_every.unwrap_or(steps)
        ))
    }

    /// `sh in.toy.sh` with `NP` in its environment.
    fn launch(&self, np: usize) -> Launch {
        Launch {
            env: vec![("NP", np.to_string())],
            program: "sh".into(),
            args: vec![SCRIPT.into()],
            reads: None,
            log: None,
        }
    }

    /// The seconds of the whole run, set-up included (a toy has no loop timer).
    fn run(&self, run: &Run, input: &str) -> anyhow::Result<f64> {
        atomic::write(&run.dir.join(SCRIPT), input.as_bytes())?;
        let start = Instant::now();
        let out = child::output(
            &mut self.launch(run.np).command(run.dir),
            OnParentDeath::Kill,
        )
        .context("cannot start sh")?;
        ensure!(
            out.status.success(),
            "toy failed ({}): {}",
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
        Ok(start.elapsed().as_secs_f64())
    }

    /// The `.data` save `save.index`.
    fn read_frame(&self, run: &Run, save: Save) -> anyhow::Result<Frame> {
        let rows = mercury::read_data(&save_file(run, "data", save.index)?)?.rows;
        Ok(Frame {
            step: save.step,
            radius: rows.iter().map(|r| r.radius).collect(),
            x: rows.iter().map(|r| r.x).collect(),
            v: rows.iter().map(|r| r.v).collect(),
            w: rows.iter().map(|r| r.w).collect(),
        })
    }

    /// The `.fstat` save `save.index` ([`super::mercury_contacts`]).
    fn read_contacts(&self, run: &Run, save: Save, s: &Snapshot) -> anyhow::Result<Vec<Contact>> {
        super::mercury_contacts(&save_file(run, "fstat", save.index)?, s)
    }
}
