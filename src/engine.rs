//! Builds a simulation from a case: the contact law is composed here, once, from the parts the
//! case switches on (normal law, clipped or not, friction or not, tangential convention).

use crate::case::{self, Case};
use crate::contact::normal::Clipped;
use crate::contact::{
    Composed, ContactLaw, Frictionless, NormalModel, NormalVisitor, Parameters, TangentialModel,
    TangentialVisitor,
};
use crate::neighbor::NeighborBuilder;
use crate::scene::Scene;
use crate::step::{Core, Engine, Simulation};
use crate::Vec3;

/// Overrides of the case's numerical settings (command line).
#[derive(Clone, Debug, Default)]
pub struct Overrides {
    pub threads: Option<usize>,
    /// Bind the team's threads to CPUs (default: yes; see [`Core::bind`]).
    pub bind: Option<bool>,
    pub skin: Option<f64>,
    pub cell: Option<f64>,
}

/// Something done with the contact law of a case, whichever concrete type it composes to.
pub trait LawVisitor {
    type Output;
    /// Does the job with the composed law `law`.
    fn visit<L: ContactLaw + Clone + 'static>(self, law: L) -> Self::Output;
}

/// Composes the contact law of `c` and hands it to `v`. Without friction the law has no
/// tangential history, torque or spin (model only what the case needs).
pub fn with_law<V: LawVisitor>(c: &case::Contact, v: V) -> V::Output {
    c.normal.with_model(&Parameters::of(c), ClipThen { c, v })
}

/// Clips the case's normal model if it asks to, then composes it with its tangential model.
struct ClipThen<'a, V> {
    c: &'a case::Contact,
    v: V,
}

impl<V: LawVisitor> NormalVisitor for ClipThen<'_, V> {
    type Output = V::Output;
    fn visit<N: NormalModel + Clone + 'static>(self, normal: N) -> V::Output {
        if self.c.clip_normal {
            with_tangential(self.c, Clipped(normal), self.v)
        } else {
            with_tangential(self.c, normal, self.v)
        }
    }
}

fn with_tangential<N, V>(c: &case::Contact, normal: N, v: V) -> V::Output
where
    N: NormalModel + Clone + 'static,
    V: LawVisitor,
{
    if c.mu <= 0.0 {
        return v.visit(Composed {
            normal,
            tangential: Frictionless,
        });
    }
    c.tangential
        .with_model(&Parameters::of(c), ComposeWith { normal, v })
}

/// Composes a normal model with the tangential model the registry builds, for a visitor.
struct ComposeWith<N, V> {
    normal: N,
    v: V,
}

impl<N, V> TangentialVisitor for ComposeWith<N, V>
where
    N: NormalModel + Clone + 'static,
    V: LawVisitor,
{
    type Output = V::Output;
    fn visit<T: TangentialModel + Clone + 'static>(self, tangential: T) -> V::Output {
        self.v.visit(Composed {
            normal: self.normal,
            tangential,
        })
    }
}

/// The parts of a simulation besides its law; the law decides the type of its contacts'
/// history, so the core is made once the law is known.
struct BuildSimulation {
    scene: Scene,
    dt: f64,
    gravity: Option<Vec3>,
    builder: NeighborBuilder,
    threads: usize,
    bind: bool,
    guard: case::Guard,
}

impl LawVisitor for BuildSimulation {
    type Output = Box<dyn Engine>;
    fn visit<L: ContactLaw + Clone + 'static>(self, law: L) -> Box<dyn Engine> {
        let mut core = Core::new(
            self.scene.domain,
            self.scene.particles,
            self.dt,
            self.gravity,
            self.builder,
            self.threads,
        );
        core.state.time = self.scene.time;
        core.params.bind = self.bind;
        core.params.guard = self.guard;
        Box::new(Simulation::new(law, core))
    }
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
    let parts = BuildSimulation {
        scene,
        dt: case.dt(),
        gravity: case.gravity().map(Vec3::from),
        builder,
        threads: o.threads.unwrap_or(case.run.threads),
        bind: o.bind.unwrap_or(true),
        guard: case.guard,
    };
    with_law(&case.contact, parts)
}
