//! `verdem run`: run a case, report its rate and stages, write its summary and, for the
//! bumpy-shear scene, coarse-grain its saves.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use verdem::analysis::cg::blocking::{self, Unit};
use verdem::analysis::cg::table::Table;
use verdem::analysis::cg::{self, plot, CgOptions};
use verdem::analysis::inrun::{self, Inrun};
use verdem::analysis::particles;
use verdem::analysis::Verdict;
use verdem::case::{Case, Scene};
use verdem::io::vtk::Particle;
use verdem::io::{atomic, checkpoint, mercury};
use verdem::run::{self, RunOptions, BENCHMARK_STEPS};
use verdem::state::Motion;
use verdem::step::Engine;

use super::args::{count, lock_output_folder, Common};
use super::signals::{self, Graceful};
use super::Finished;

#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    common: Common,
    #[command(flatten)]
    reports: super::args::Reports,
    /// The run ends at this step (default: the case's `run.steps`), also after --resume.
    #[arg(long)]
    steps: Option<u64>,
    /// Output folder (default: out/NAME; with --resume, the checkpoint's folder).
    #[arg(long)]
    out: Option<PathBuf>,
    /// A save every N steps (default: the case's `run.save_every`).
    #[arg(long, value_parser = count::<u64>)]
    save_every: Option<u64>,
    /// Write a checkpoint every N steps (0 = never).
    #[arg(long, default_value_t = 0)]
    checkpoint_every: u64,
    /// Continue from a checkpoint written by --checkpoint-every (its folder holds the run's
    /// saves by design; saves after the checkpoint's step are written again).
    #[arg(long)]
    resume: Option<PathBuf>,
    /// Replace the files of an earlier run of the same name in the output folder (without it,
    /// such a folder is refused and nothing is written).
    #[arg(long)]
    force: bool,
    /// Also write each save as a ParaView file, NAME.NNNN.vtu, listed in NAME.pvd (as
    /// `[output] vtk = true` in the case).
    #[arg(long)]
    vtk: bool,
    /// In-run averaging of the bumpy-shear profiles: sample the contact stress every K steps
    /// (0 = no in-run averaging; default: 8 free–free contact durations). The contact columns'
    /// errors are calibrated at the default and at `--inrun-every 25 --inrun-particle-every
    /// 1200` (smaller errors, ~1 % more cost); at any other sampling they are marked not to be
    /// trusted (docs/statistics.md).
    #[arg(long)]
    inrun_every: Option<u64>,
    /// Sample the particle fields of the in-run profiles every KP steps, a multiple of
    /// --inrun-every (default: the multiple nearest to 20 contact durations).
    #[arg(long)]
    inrun_particle_every: Option<u64>,
    /// No progress bar.
    #[arg(long)]
    quiet: bool,
}

/// The fraction of the guard's overlap limit beyond which a run that reached it is warned about.
const OVERLAP_WARNING: f64 = 0.5;

pub fn exec(a: Args) -> anyhow::Result<Finished> {
    let (case, mut engine) = a.common.load()?;
    for warning in case.warnings() {
        eprintln!("warning: {warning}");
    }
    print_contact_summary(&case);
    let tag = checkpoint::tag(&case);
    let resumed = match &a.resume {
        Some(ck) => {
            let r = checkpoint::read_run(ck, engine.as_mut(), &tag)?;
            for lack in r.lacks() {
                eprintln!("warning: {}: {lack}", ck.display());
            }
            println!(
                "resumed at step {} (t = {})",
                engine.state().step,
                engine.state().time
            );
            Some((ck.as_path(), r))
        }
        None => None,
    };
    let end_step = a.steps.unwrap_or(case.run.steps);
    if end_step < engine.state().step {
        anyhow::bail!(
            "the run would end at step {end_step} ({}), before the checkpoint's step {}",
            if a.steps.is_some() {
                "--steps"
            } else {
                "the case's run.steps"
            },
            engine.state().step
        );
    }
    let out_dir = match (a.out, &a.resume) {
        (Some(out), _) => out,
        (None, Some(ck)) => checkpoint_folder(ck).to_path_buf(),
        (None, None) => PathBuf::from("out").join(&case.name),
    };
    let lock = lock_output_folder(&out_dir)?;
    // A resumed run continues in its checkpoint's folder, which holds its saves by design.
    let own_folder = |ck: &PathBuf| {
        let canonical = |p: &Path| std::fs::canonicalize(p).ok();
        canonical(checkpoint_folder(ck)) == canonical(&out_dir)
    };
    if !a.resume.as_ref().is_some_and(own_folder) {
        let removed = run::claim_output_folder(&out_dir, &case.name, a.force, "--force", &lock)?;
        if removed > 0 {
            println!(
                "removed the {removed} files of an earlier run {:?} from {} (--force)",
                case.name,
                out_dir.display()
            );
        }
    }
    let opts = RunOptions {
        end_step,
        save_every: a.save_every.unwrap_or(case.run.save_every),
        checkpoint_every: a.checkpoint_every,
        out_dir,
        name: case.name.clone(),
        tag,
        progress: !a.quiet,
        write_saves: true,
        vtk: a.vtk || case.output.vtk,
        stop: Some(stop_on_signal()?),
    };
    let shear = matches!(case.scene, Scene::BumpyShear { .. });
    let mut inrun = if shear {
        in_run(
            (a.inrun_every, a.inrun_particle_every),
            &case,
            engine.as_ref(),
            &opts,
            resumed.as_ref(),
        )?
    } else {
        None
    };
    let observer = inrun.as_mut().map(|i| i as &mut dyn run::Observer);
    let s = match &resumed {
        Some((_, r)) => run::run_resumed(engine.as_mut(), &opts, r, observer)?,
        None => run::run_observed(engine.as_mut(), &opts, false, observer)?,
    };
    let limit = engine.params().guard.overlap;
    if s.deepest_overlap > OVERLAP_WARNING * limit {
        eprintln!(
            "warning: the largest overlap reached {:.3e} of the smaller radius, beyond {} of the \
             run guard's limit {limit}: the contacts are soft for these speeds, or the step is \
             coarse (the guard stops a run at the limit)",
            s.deepest_overlap, OVERLAP_WARNING
        );
    }
    if s.interrupted {
        let ck = run::checkpoint_path(&opts.out_dir, &opts.name);
        println!(
            "interrupted at step {} (t = {}) after {} saves; checkpoint {}",
            s.step,
            s.time,
            s.saves,
            ck.display()
        );
        println!("continue with: {}", resume_command(&ck));
        return Ok(Finished::Interrupted);
    }
    println!(
        "done: step {} t = {} saves {} in {}",
        s.step,
        s.time,
        s.saves,
        opts.out_dir.display()
    );
    let threads = engine.params().threads;
    if s.steps_run > 0 {
        let projection = if shear {
            format!(
                "; the full 2e8-step benchmark would take {:.2} h at this rate",
                s.hours_for(BENCHMARK_STEPS)
            )
        } else {
            String::new()
        };
        println!(
            "rate: {:.0} steps/s on {threads} thread(s) ({:.1} s){projection}",
            s.rate(),
            s.seconds,
        );
    } else {
        println!("rate: no steps run");
    }
    let st = &s.stages;
    let ms = |ns: u64| ns as f64 * 1e-6;
    println!(
        "stages (thread 0): neighbour {:.0} ms ({} rebuilds), forces {:.0} ms, gather+integrate {:.0} ms, barrier wait {:.0} ms; {} pairs in the list",
        ms(st.neighbor),
        st.rebuilds,
        ms(st.forces),
        ms(st.integrate),
        ms(st.wait),
        engine.pair_count()
    );
    let guard = engine.params().guard;
    println!(
        "run guard: largest overlap {:.3e} of the smaller radius (limit {}), largest energy a \
         contact gave beyond what it took {:.3e} of what it took (limit {})",
        s.deepest_overlap, guard.overlap, s.largest_excess, guard.contact
    );
    println!("state hash: {}", s.hash);
    run::write_summary(&opts.out_dir, &case.name, &s, threads)?;
    if let Some(png) = particles_picture(&opts, engine.as_ref())? {
        println!("particles: {}", png.display());
    }
    // The checks printed, for the reports a CI system reads: none without profiles.
    let mut verdicts = Vec::new();
    if s.saves > 0 && shear {
        let (saved, checks, mut report) =
            cg::write_all(&opts.out_dir.join(&case.name), &CgOptions::for_case(&case))?;
        verdicts.extend(checks.into_iter().map(|c| Verdict {
            case: "saves".into(),
            ..c
        }));
        println!(
            "profiles: {}",
            opts.out_dir
                .join(format!("{}.profiles.csv", case.name))
                .display()
        );
        if let Some(r) = inrun.as_ref().and_then(inrun::Inrun::result) {
            let path = inrun::csv_path(&opts.out_dir, &case.name);
            atomic::write(&path, inrun::csv(&r).as_bytes())?;
            let errors = inrun::errors_csv_path(&opts.out_dir, &case.name);
            atomic::write(&errors, inrun::errors_csv(&r).as_bytes())?;
            println!("in-run profiles: {}", path.display());
            let png = opts.out_dir.join(format!("{}.profiles.png", case.name));
            plot::run_png(&Table::of(&saved), &Table::of(&r.profiles), &png)?;
            let units: Vec<Unit> = saved.per_save.iter().cloned().map(Unit::of_save).collect();
            let floor = blocking::Floor::reference(opts.save_every as f64 * case.dt());
            let save_errors = blocking::field_errors_with_floor(&units, &saved.grid, &floor);
            let (text, inrun_verdicts) = inrun::report(&r, &saved, &save_errors);
            report.push_str(&text);
            verdicts.extend(inrun_verdicts);
            let checks = opts.out_dir.join(format!("{}.checks.txt", case.name));
            atomic::write(&checks, report.as_bytes())?;
        }
        print!("{report}");
    } else if s.saves > 0 {
        println!(
            "profiles: none (the z-profiles and their checks describe the bumpy-shear \
             scene; `verdem cg` coarse-grains these saves all the same)"
        );
    }
    a.reports
        .write("verdem run", &verdicts, |c| cg::checks::result(c).into())?;
    Ok(Finished::Done)
}

/// The in-run averaging of a bumpy-shear run, over the steps of the saves `verdem cg` takes by
/// default (the second half of the run's saves), or `None` with `--inrun-every 0`. `every` and
/// `particle_every` are the command line's intervals, when given. A run `resumed` from a
/// checkpoint continues the sums it holds; one that holds none (warned on stderr) starts them at
/// the resume.
fn in_run(
    (every, particle_every): (Option<u64>, Option<u64>),
    case: &Case,
    engine: &dyn Engine,
    opts: &RunOptions,
    resumed: Option<&(&Path, checkpoint::Resumed)>,
) -> anyhow::Result<Option<Inrun>> {
    let start = engine.state().step;
    // Intervals in contact durations (docs/statistics.md).
    let (every, particle_every) = inrun::intervals(case, every, particle_every);
    if every == 0 {
        return Ok(None);
    }
    // The saves cg averages by default: the second half of those the folder will hold.
    let first = if resumed.is_some() {
        run::saves_of(&opts.out_dir, &opts.name)?
            .first()
            .copied()
            .unwrap_or(0)
    } else {
        start.div_ceil(opts.save_every)
    };
    let mut inrun = Inrun::for_run(case, engine, opts, (every, particle_every), first)?;
    if let Some((ck, r)) = resumed {
        let file = ck.display().to_string();
        match &r.record.observer {
            Some(sums) => {
                if let Some(why) = inrun.restore(&file, r.observer_at, sums, start)? {
                    eprintln!(
                        "warning: {file}: {why}: the in-run profiles average only the steps \
                         after step {}",
                        inrun.sampling().from
                    );
                }
            }
            None if inrun.sampling().from == start => eprintln!(
                "warning: {file}: the checkpoint holds no in-run sums: the in-run profiles cover \
                 only the steps after the resume (step {start})"
            ),
            None => {}
        }
    }
    Ok(Some(inrun))
}

/// Draws the last save in the output folder as `NAME.particles.png` (none when the folder has
/// no save); the wall spheres are the state's prescribed ones (in id order, as the save).
/// Returns the picture's path.
fn particles_picture(opts: &RunOptions, engine: &dyn Engine) -> anyhow::Result<Option<PathBuf>> {
    let Some(&k) = run::saves_of(&opts.out_dir, &opts.name)?.last() else {
        return Ok(None);
    };
    let data = mercury::read_data(&mercury::save_path(&opts.out_dir, &opts.name, "data", k))?;
    let motion = engine.snapshot().particles.motion;
    let particles: Vec<Particle> = data
        .rows
        .iter()
        .enumerate()
        .map(|(a, r)| Particle {
            x: r.x,
            v: r.v,
            w: r.w,
            radius: r.radius,
            wall: motion.get(a).is_some_and(|m| *m != Motion::Free),
        })
        .collect();
    let png = opts.out_dir.join(format!("{}.particles.png", opts.name));
    let title = format!(
        "{}: save {k}, t = {:.3}; side view (x, z), colour vx",
        opts.name, data.time
    );
    particles::particles_png(&particles, &data.domain_lo, &data.domain_hi, &title, &png)?;
    Ok(Some(png))
}

/// Prints the derived contact numbers so a user sees at once whether a contact is resolved.
fn print_contact_summary(case: &Case) {
    let m = case.particle_mass();
    let dt = case.dt();
    for (label, meff) in [("free-free", 0.5 * m), ("free-wall", m)] {
        if let (Some(tc), Some(e)) = (case.collision_time(meff), case.restitution(meff)) {
            println!("{label}: tc = {tc:.6e}, e = {e:.5}, tc/dt = {:.2}", tc / dt);
        }
    }
    println!("dt = {dt:e}");
}

/// A flag raised by SIGINT, SIGTERM or SIGHUP ([`signals`]): a run then stops at the end of its
/// block of steps and writes a checkpoint. A second signal ends the process at once with
/// [`super::EXIT_INTERRUPTED`]; every file it has written is whole (written atomically) all the
/// same.
fn stop_on_signal() -> anyhow::Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    signals::graceful(Graceful {
        flag: Arc::clone(&stop),
        notice: Some(
            "\nstopping: writing a checkpoint at the end of the steps under way \
             (a second signal stops at once, without it)",
        ),
        second_exits: true,
    })?;
    Ok(stop)
}

/// The folder of the checkpoint `ck` (`.` for a bare file name), which holds its run's saves.
fn checkpoint_folder(ck: &Path) -> &Path {
    ck.parent()
        .filter(|d| !d.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
}

/// This process's command line with `--resume CHECKPOINT` in place of any `--resume` it had,
/// quoted for a POSIX shell.
fn resume_command(checkpoint: &Path) -> String {
    let mut args: Vec<String> = Vec::new();
    let mut skip = false;
    for a in std::env::args() {
        if std::mem::take(&mut skip) {
            continue;
        }
        if a == "--resume" {
            skip = true;
        } else if !a.starts_with("--resume=") {
            args.push(a);
        }
    }
    args.push("--resume".into());
    args.push(checkpoint.display().to_string());
    let quote = |a: &String| {
        let plain = a
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || "-_./=:,+".contains(c));
        if plain && !a.is_empty() {
            a.clone()
        } else {
            format!("'{}'", a.replace('\'', r"'\''"))
        }
    };
    args.iter().map(quote).collect::<Vec<_>>().join(" ")
}
