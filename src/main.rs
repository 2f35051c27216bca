//! The `verdem` command line.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use anyhow::Context;
use clap::{Parser, Subcommand};

use verdem::analysis::cg::{self, table::Table, CgOptions, KernelChoice};
use verdem::case::Case;
use verdem::engine::{self, Overrides};
use verdem::run::{self, RunOptions};
use verdem::{bench, checkpoint, hash, scene};

#[derive(Parser)]
#[command(
    name = "verdem",
    version,
    about = "Deterministic DEM solver, verification harness and benchmark suite"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(clap::Args, Clone)]
struct Common {
    /// Case file (TOML).
    case: PathBuf,
    /// Initial configuration: official `GranularShearFlow.data` or a MercuryCG `.data` save.
    #[arg(long)]
    init: Option<PathBuf>,
    /// Worker threads of the time step.
    #[arg(long, value_parser = count::<usize>)]
    threads: Option<usize>,
    /// Leave the threads to the scheduler: by default thread t of a team of two or more runs on
    /// the t-th CPU the process may use (start two multi-threaded runs side by side with
    /// `taskset -c` on disjoint CPUs).
    #[arg(long)]
    no_bind: bool,
    /// Pair-list skin (length).
    #[arg(long, allow_negative_numbers = true, value_parser = positive)]
    skin: Option<f64>,
    /// Cell edge of the neighbour grid (length; raised to 2 r_max + skin).
    #[arg(long, allow_negative_numbers = true, value_parser = non_negative)]
    cell: Option<f64>,
}

#[derive(Subcommand)]
enum Command {
    /// Run a case: MercuryCG saves, diagnostics table, final state hash.
    Run {
        #[command(flatten)]
        common: Common,
        /// The run ends at this step (default: the case's `run.steps`), also after --resume.
        #[arg(long)]
        steps: Option<u64>,
        /// Output folder (default: out/NAME).
        #[arg(long)]
        out: Option<PathBuf>,
        /// A save every N steps (default: the case's `run.save_every`).
        #[arg(long, value_parser = count::<u64>)]
        save_every: Option<u64>,
        /// Write a checkpoint every N steps (0 = never).
        #[arg(long, default_value_t = 0)]
        checkpoint_every: u64,
        /// Continue from a checkpoint written by --checkpoint-every.
        #[arg(long)]
        resume: Option<PathBuf>,
        /// No progress bar.
        #[arg(long)]
        quiet: bool,
    },
    /// Coarse-grain a MercuryCG series into z-profiles with error bars, checks and a plot.
    Cg {
        /// Series base name: DIR/NAME for DIR/NAME.data.NNNN and DIR/NAME.fstat.NNNN.
        base: PathBuf,
        /// First save (default: the second half of the series).
        #[arg(long)]
        from: Option<u64>,
        /// Last save (default: the last).
        #[arg(long)]
        to: Option<u64>,
        #[arg(long, default_value_t = 100, value_parser = count::<usize>)]
        slices: usize,
        #[arg(long, value_enum, default_value_t = KernelChoice::Heaviside)]
        kernel: KernelChoice,
        /// Kernel width: Gauss standard deviation or Lucy cutoff (default: the slice height).
        #[arg(long, allow_negative_numbers = true, value_parser = positive)]
        width: Option<f64>,
        /// Case file telling which particles are walls and the density (default: the
        /// benchmark's, ids 1-480 walls, density 1).
        #[arg(long)]
        case: Option<PathBuf>,
        /// Blocks of saves for the standard errors.
        #[arg(long, default_value_t = 10, value_parser = count::<usize>)]
        blocks: usize,
    },
    /// Time verdem against the installed LAMMPS and LIGGGHTS on the same case and state.
    Bench {
        /// Case file (default: cases/shear_flow_quick.toml).
        case: Option<PathBuf>,
        /// State to start from (default: MercuryDPM's developed state).
        #[arg(long, default_value = "data/states/mercury_t143.85.data")]
        from: PathBuf,
        #[arg(long, default_value_t = 20_000, value_parser = count::<u64>)]
        steps: u64,
        /// verdem thread counts.
        #[arg(long, value_delimiter = ',', default_value = "1,2", value_parser = count::<usize>)]
        threads: Vec<usize>,
        /// Peers to run (none: --peers '').
        #[arg(long, value_delimiter = ',', default_value = "lammps,liggghts")]
        peers: Vec<String>,
        /// MPI ranks for the peers.
        #[arg(long, value_delimiter = ',', default_value = "1,2", value_parser = count::<usize>)]
        np: Vec<usize>,
        /// Alternating rounds.
        #[arg(long, default_value_t = 3, value_parser = count::<usize>)]
        rounds: usize,
        /// Skip the ceiling rows: two independent 1-thread verdem runs at once, which measures
        /// what this machine gives two jobs that share nothing, and the same two runs waiting
        /// for each other once a step, which measures what it gives two that meet once a step
        /// as a team's threads do.
        #[arg(long)]
        no_ceiling: bool,
        /// Where the table (bench.md, bench.csv) and the peers' inputs go.
        #[arg(long, default_value = "out/bench")]
        out: PathBuf,
    },
    /// Run the verification cases and print expected, measured, tolerance and PASS/FAIL.
    Verify {
        /// The folder of the verification cases.
        #[arg(long, default_value = "cases/verify")]
        cases: PathBuf,
        /// Only the rows whose case name contains this text.
        #[arg(long)]
        only: Option<String>,
        /// Also run the binary collisions in these installed peers (lammps, liggghts), against
        /// the same closed forms.
        #[arg(long, value_enum, value_delimiter = ',')]
        peers: Vec<verdem::peers::Peer>,
        /// Where the peers' collision runs go.
        #[arg(long, default_value = "out/verify")]
        out: PathBuf,
    },
    /// Compare profiles tables (`verdem cg` output, e.g. golden/peers/*.profiles.csv) with a
    /// reference over the core: χ²/dof and relative difference of the core means of each
    /// benchmark profile.
    Compare {
        /// The reference table.
        reference: PathBuf,
        /// The tables to compare with it (same grid).
        #[arg(required = true)]
        others: Vec<PathBuf>,
        /// Also overlay all the tables' profiles (±2 SE bands) in this PNG.
        #[arg(long)]
        plot: Option<PathBuf>,
        /// Labels of the tables in the plot and the table, reference first (default: the
        /// file names).
        #[arg(long, value_delimiter = ',')]
        labels: Vec<String>,
    },
    /// Run LAMMPS or LIGGGHTS and verdem (with the peer's tangential convention) on the same
    /// case and state; compare positions, velocities and spins at every save; write both
    /// series as MercuryCG saves and the table as OUT/cross.md.
    Cross {
        /// The peer: lammps (`lmp`) or liggghts (`liggghts`), run with mpirun.
        #[arg(value_enum)]
        peer: verdem::peers::Peer,
        /// Case file (default: cases/shear_flow_quick.toml).
        #[arg(default_value = "cases/shear_flow_quick.toml")]
        case: PathBuf,
        /// State to start from.
        #[arg(long, default_value = "data/states/mercury_t143.85.data")]
        from: PathBuf,
        #[arg(long, default_value_t = 20000, value_parser = count::<u64>)]
        steps: u64,
        /// A save every N steps.
        #[arg(long, default_value_t = 2000, value_parser = count::<u64>)]
        every: u64,
        /// MPI ranks of the peer (and verdem's threads).
        #[arg(long, default_value_t = 2, value_parser = count::<usize>)]
        np: usize,
        #[arg(long, default_value = "out/cross")]
        out: PathBuf,
        /// Run verdem with this tangential convention instead of the peer's (to see what a
        /// convention changes).
        #[arg(long, value_enum)]
        convention: Option<verdem::case::Tangential>,
    },
    /// The speed/accuracy trade: the case under variants (dt, softer contacts, skin, threads)
    /// from the same state for the same simulated time; cost, restitution error and the
    /// deviation of each profile from the reference in units of its standard error.
    Tradeoff {
        /// Case file.
        #[arg(default_value = "cases/shear_flow_quick.toml")]
        case: PathBuf,
        /// State to start from.
        #[arg(long, default_value = "data/states/mercury_t143.85.data")]
        from: PathBuf,
        /// Simulated time of every variant (time units).
        #[arg(long, default_value_t = 20.0, allow_negative_numbers = true, value_parser = positive)]
        time: f64,
        /// Saves of every variant (all are coarse-grained).
        #[arg(long, default_value_t = 40, value_parser = count::<u64>)]
        saves: u64,
        #[arg(long, default_value = "out/tradeoff")]
        out: PathBuf,
        /// The two-sphere case whose restitution each variant's law is measured on.
        #[arg(long, default_value = "cases/verify/binary_collision.toml")]
        pair: PathBuf,
    },
    /// Drive one contact of the case's law through a prescribed motion (MOTION.csv: t, then
    /// x,y,z, qw,qx,qy,qz, vx,vy,vz, wx,wy,wz of sphere 1 and of sphere 2) and write the forces
    /// and torques on each sphere at every row (FORCES.csv).
    Kinematics {
        /// Case file: material, radii (from its two spheres) and contact law.
        case: PathBuf,
        /// Motion file (CSV with a header line).
        motion: PathBuf,
        /// Forces file to write.
        #[arg(long)]
        out: PathBuf,
        /// Velocities of the increment over a step: from positions and quaternions (what
        /// verdem's integrator feeds its law) or the mean of the two rows' velocities.
        #[arg(long, value_enum, default_value_t = verdem::kinematics::Increment::Positions)]
        increment: verdem::kinematics::Increment,
    },
    /// Print the SHA-256 of the full state after N steps (no files written).
    Hash {
        #[command(flatten)]
        common: Common,
        #[arg(long)]
        steps: u64,
    },
}

/// Exit status of a run stopped by a signal after writing its checkpoint (128 + SIGINT, as a
/// shell reports a process that SIGINT ended).
const EXIT_INTERRUPTED: i32 = 130;

fn main() {
    match real_main() {
        Ok(Finished::Done) => {}
        Ok(Finished::Interrupted) => std::process::exit(EXIT_INTERRUPTED),
        Err(e) => {
            eprintln!("error: {e:#}");
            std::process::exit(1);
        }
    }
}

/// How a command ended, when it did not fail.
enum Finished {
    Done,
    /// A run stopped by a signal, its checkpoint written.
    Interrupted,
}

/// A flag raised by SIGINT, SIGTERM or SIGHUP (ctrlc's `termination` feature): a run then stops
/// at the end of its block of steps and writes a checkpoint. A second signal ends the process at
/// once; every file it has written is whole (written atomically) all the same.
fn stop_on_signal() -> anyhow::Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&stop);
    ctrlc::set_handler(move || {
        if flag.swap(true, Ordering::Relaxed) {
            std::process::exit(EXIT_INTERRUPTED);
        }
        eprintln!(
            "\nstopping: writing a checkpoint at the end of the steps under way \
             (a second signal stops at once, without it)"
        );
    })
    .context("cannot install the signal handler")?;
    Ok(stop)
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

/// A count of one or more (threads, ranks, rounds, slices, blocks, steps between saves).
fn count<T: std::str::FromStr<Err = std::num::ParseIntError> + PartialOrd + From<u8>>(
    s: &str,
) -> Result<T, String> {
    let v: T = s.parse().map_err(|e| format!("{e}"))?;
    if v >= T::from(1) {
        Ok(v)
    } else {
        Err(format!("must be 1 or more, got {s}"))
    }
}

/// A length or time that must be positive and finite.
fn positive(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|e| format!("{e}"))?;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!("must be positive and finite, got {s}"))
    }
}

/// A length that must be zero or positive, and finite.
fn non_negative(s: &str) -> Result<f64, String> {
    let v: f64 = s.parse().map_err(|e| format!("{e}"))?;
    if v.is_finite() && v >= 0.0 {
        Ok(v)
    } else {
        Err(format!("must be zero or positive and finite, got {s}"))
    }
}

fn load(common: &Common) -> anyhow::Result<(Case, Box<dyn verdem::sim::Engine>)> {
    let case = Case::load(&common.case)?;
    let scene = scene::build(&case, common.init.as_deref())?;
    let o = Overrides {
        threads: common.threads,
        bind: common.no_bind.then_some(false),
        skin: common.skin,
        cell: common.cell,
    };
    let engine = engine::build(&case, scene, &o);
    if let Some(warning) = verdem::team::oversubscribed(engine.core().threads) {
        eprintln!("warning: {warning}");
    }
    Ok((case, engine))
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

fn real_main() -> anyhow::Result<Finished> {
    match Cli::parse().command {
        Command::Run {
            common,
            steps,
            out,
            save_every,
            checkpoint_every,
            resume,
            quiet,
        } => {
            let (case, mut engine) = load(&common)?;
            print_contact_summary(&case);
            let tag = format!("{}:{}", case.name, engine.core().particles.len());
            if let Some(ck) = &resume {
                checkpoint::read(ck, engine.core_mut(), &tag)?;
                println!(
                    "resumed at step {} (t = {})",
                    engine.core().step,
                    engine.core().time
                );
            }
            let end_step = steps.unwrap_or(case.run.steps);
            if end_step < engine.core().step {
                anyhow::bail!(
                    "the run would end at step {end_step} ({}), before the checkpoint's step {}",
                    if steps.is_some() {
                        "--steps"
                    } else {
                        "the case's run.steps"
                    },
                    engine.core().step
                );
            }
            let opts = RunOptions {
                end_step,
                save_every: save_every.unwrap_or(case.run.save_every),
                checkpoint_every,
                out_dir: out.unwrap_or_else(|| PathBuf::from("out").join(&case.name)),
                name: case.name.clone(),
                tag,
                progress: !quiet,
                write_saves: true,
                stop: Some(stop_on_signal()?),
            };
            let s = run::run(engine.as_mut(), &opts, resume.is_some())?;
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
            let shear = matches!(case.scene, verdem::case::Scene::BumpyShear { .. });
            if s.steps_run > 0 {
                let projection = if shear {
                    format!(
                        "; the full 2e8-step benchmark would take {:.2} h at this rate",
                        2e8 / s.rate() / 3600.0
                    )
                } else {
                    String::new()
                };
                println!(
                    "rate: {:.0} steps/s on {} thread(s) ({:.1} s){projection}",
                    s.rate(),
                    engine.core().threads,
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
                engine.core().pairs.p.len()
            );
            println!("state hash: {}", s.hash);
            let summary = format!(
                "case = {:?}\nstep = {}\ntime = {}\nhash = {:?}\nthreads = {}\nsteps_per_second = {}\n",
                case.name,
                s.step,
                s.time,
                s.hash,
                engine.core().threads,
                s.rate()
            );
            let p = opts.out_dir.join(format!("{}.summary.toml", case.name));
            verdem::io::atomic::write(&p, summary.as_bytes())
                .with_context(|| p.display().to_string())?;
            if s.saves > 0 && shear {
                let (_, report) =
                    cg::write_all(&opts.out_dir.join(&case.name), &CgOptions::for_case(&case))?;
                println!(
                    "profiles: {}",
                    opts.out_dir
                        .join(format!("{}.profiles.csv", case.name))
                        .display()
                );
                print!("{report}");
            } else if s.saves > 0 {
                println!(
                    "profiles: none (the z-profiles and their checks describe the bumpy-shear \
                     scene; `verdem cg` coarse-grains these saves all the same)"
                );
            }
        }
        Command::Cg {
            base,
            from,
            to,
            slices,
            kernel,
            width,
            case,
            blocks,
        } => {
            let mut o = match case {
                Some(c) => CgOptions::for_case(&Case::load(&c)?),
                None => CgOptions {
                    from: None,
                    to: None,
                    slices: 100,
                    kernel: KernelChoice::Heaviside,
                    width: None,
                    walls: 480,
                    density: 1.0,
                    periodic: [true, true, false],
                    blocks: 10,
                },
            };
            o.from = from;
            o.to = to;
            o.slices = slices;
            o.kernel = kernel;
            o.width = width;
            o.blocks = blocks;
            let (_, report) = cg::write_all(&base, &o)?;
            print!("{report}");
        }
        Command::Bench {
            case,
            from,
            steps,
            threads,
            peers,
            np,
            rounds,
            no_ceiling,
            out,
        } => {
            let case =
                Case::load(&case.unwrap_or_else(|| PathBuf::from("cases/shear_flow_quick.toml")))?;
            for warning in threads
                .iter()
                .filter_map(|&t| verdem::team::oversubscribed(t))
            {
                eprintln!("warning: {warning}");
            }
            let mut configs: Vec<bench::Config> = threads
                .iter()
                .map(|&t| bench::Config::Verdem {
                    threads: t,
                    copies: 1,
                    lockstep: false,
                })
                .collect();
            if !no_ceiling {
                configs.extend([false, true].map(|lockstep| bench::Config::Verdem {
                    threads: 1,
                    copies: 2,
                    lockstep,
                }));
            }
            for name in peers.iter().filter(|p| !p.is_empty()) {
                let peer = match name.as_str() {
                    "lammps" => verdem::peers::Peer::Lammps,
                    "liggghts" => verdem::peers::Peer::Liggghts,
                    other => anyhow::bail!("--peers: unknown peer {other:?} (lammps, liggghts)"),
                };
                configs.extend(np.iter().map(|&n| bench::Config::Peer { peer, np: n }));
            }
            let measured = bench::run(&case, &from, steps, &configs, rounds, &out)?;
            let particles = scene::build(&case, Some(&from))?.particles.len();
            let md = bench::markdown(&measured, particles);
            let cpu = std::fs::read_to_string("/proc/cpuinfo")
                .ok()
                .and_then(|c| {
                    c.lines()
                        .find(|l| l.starts_with("model name"))
                        .map(|l| l.split(':').nth(1).unwrap_or("").trim().to_string())
                })
                .unwrap_or_default();
            let header = format!(
                "{steps} steps of {} from {}, {rounds} alternating rounds, {} cores ({cpu}), no file output in the timed region

",
                case.name,
                from.display(),
                std::thread::available_parallelism().map(|n| n.get()).unwrap_or(0)
            );
            print!("{header}{md}");
            verdem::io::atomic::write(&out.join("bench.md"), (header + &md).as_bytes())?;
            verdem::io::atomic::write(
                &out.join("bench.csv"),
                bench::csv(&measured, particles).as_bytes(),
            )?;
        }
        Command::Verify {
            cases,
            only,
            peers,
            out,
        } => {
            let mut rows = verdem::verify::all(&cases)?;
            let collision = Case::load(&cases.join("binary_collision.toml"))?;
            for peer in peers {
                let dir = out.join(peer.binary());
                rows.extend(verdem::peers::collision::rows(peer, &collision, &dir)?);
            }
            if let Some(only) = only {
                rows.retain(|r| r.case.contains(&only));
                if rows.is_empty() {
                    anyhow::bail!("--only {only:?}: no verification row's case contains it");
                }
            }
            print!("{}", verdem::verify::table(&rows));
            let passed = rows.iter().filter(|r| r.passed()).count();
            let failed = verdem::verify::failures(&rows);
            println!(
                "{passed} passed, {failed} failed, {} known defects of peer conventions (FAIL*)",
                rows.len() - passed - failed
            );
            if failed > 0 {
                std::process::exit(1);
            }
        }
        Command::Cross {
            peer,
            case,
            from,
            steps,
            every,
            np,
            out,
            convention,
        } => {
            let case = Case::load(&case)?;
            let out = out.join(peer.binary());
            let convention = convention.unwrap_or(verdem::peers::cross::convention_of(peer));
            let report = verdem::peers::cross::cross(
                peer, &case, convention, &from, steps, every, np, &out,
            )?;
            print!("{}", report.markdown());
            println!("(saves and tables in {})", out.display());
        }
        Command::Compare {
            reference,
            others,
            plot,
            labels,
        } => {
            let paths: Vec<&PathBuf> = std::iter::once(&reference).chain(&others).collect();
            anyhow::ensure!(
                labels.is_empty() || labels.len() == paths.len(),
                "--labels: {} labels for {} tables",
                labels.len(),
                paths.len()
            );
            let mut tables = Vec::new();
            for (k, p) in paths.iter().enumerate() {
                let label = labels
                    .get(k)
                    .cloned()
                    .unwrap_or_else(|| p.display().to_string());
                tables.push((label, Table::read(p)?));
            }
            let rows = verdem::analysis::cg::compare::compare(&tables[0].1, &tables[1..])?;
            print!(
                "{}",
                verdem::analysis::cg::compare::markdown(&tables[0].0, &rows)
            );
            if let Some(png) = plot {
                let runs: Vec<(&str, &Table)> =
                    tables.iter().map(|(l, t)| (l.as_str(), t)).collect();
                cg::plot::overlay_png(&runs, &png)?;
                println!("(overlay in {})", png.display());
            }
        }
        Command::Tradeoff {
            case,
            from,
            time,
            saves,
            out,
            pair,
        } => {
            let case = Case::load(&case)?;
            let pair = Case::load(&pair)?;
            let outcomes = verdem::analysis::tradeoff::run(&case, &pair, &from, time, saves, &out)?;
            let table = verdem::analysis::tradeoff::markdown(&outcomes);
            verdem::io::atomic::write(&out.join("tradeoff.md"), table.as_bytes())?;
            print!("{table}");
        }
        Command::Kinematics {
            case,
            motion,
            out,
            increment,
        } => {
            let case = Case::load(&case)?;
            let (file, text) = verdem::io::read_text(&motion)?;
            let rows = verdem::kinematics::parse_motion(&file, &text)?;
            let (_, radius) = verdem::kinematics::pair_of(&case)?;
            let law = verdem::kinematics::law_of(&case);
            let forces = verdem::kinematics::drive(law.as_ref(), radius, &rows, increment);
            verdem::io::atomic::write(&out, verdem::kinematics::forces_csv(&forces).as_bytes())?;
            println!(
                "{} rows of {} ({} convention{}) -> {}",
                forces.len(),
                case.name,
                case.contact.tangential.name(),
                if case.contact.clip_normal {
                    ", clipped normal force"
                } else {
                    ""
                },
                out.display()
            );
        }
        Command::Hash { common, steps } => {
            let (_, mut engine) = load(&common)?;
            engine.advance(steps);
            println!("{}", hash::state_hash(&engine.core().snapshot()));
        }
    }
    Ok(Finished::Done)
}
