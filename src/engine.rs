//! Builds a simulation from a case: the contact law is composed here, once, from the parts the
//! case switches on (friction or not, clipped normal force or not).

use crate::case::{Case, Tangential};
use crate::contact::normal::Clipped;
use crate::contact::{Composed, Frictionless, LinearSpringDashpot, MercurySlidingFriction};
use crate::neighbor::NeighborBuilder;
use crate::scene::Scene;
use crate::sim::{Core, Engine, Simulation};
use crate::Vec3;

/// Overrides of the case's numerical settings (command line).
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    pub threads: Option<usize>,
    pub skin: Option<f64>,
    pub cell: Option<f64>,
}

/// A ready-to-run simulation of `scene` under the case's contact law.
pub fn build(case: &Case, scene: Scene, o: &Overrides) -> Box<dyn Engine> {
    let r_max = scene.particles.radius.iter().cloned().fold(0.0, f64::max);
    let builder = NeighborBuilder::new(
        o.skin.unwrap_or(case.neighbor.skin),
        o.cell.unwrap_or(case.neighbor.cell),
        r_max,
        case.neighbor.search,
    );
    let mut core = Core::new(
        scene.domain,
        scene.particles,
        case.dt(),
        case.gravity().map(Vec3::from),
        builder,
        o.threads.unwrap_or(case.run.threads),
    );
    core.time = scene.time;
    let c = &case.contact;
    let normal = LinearSpringDashpot {
        kn: c.kn,
        gamman: c.gamman,
    };
    let friction = match c.tangential {
        Tangential::Mercury => MercurySlidingFriction {
            kt: c.kt,
            gammat: c.gammat,
            mu: c.mu,
        },
    };
    // Model only what the case needs: without friction no tangential history, torque or spin.
    match (c.mu > 0.0, c.clip_normal) {
        (true, false) => Box::new(Simulation::new(
            Composed {
                normal,
                tangential: friction,
            },
            core,
        )),
        (true, true) => Box::new(Simulation::new(
            Composed {
                normal: Clipped(normal),
                tangential: friction,
            },
            core,
        )),
        (false, false) => Box::new(Simulation::new(
            Composed {
                normal,
                tangential: Frictionless,
            },
            core,
        )),
        (false, true) => Box::new(Simulation::new(
            Composed {
                normal: Clipped(normal),
                tangential: Frictionless,
            },
            core,
        )),
    }
}
