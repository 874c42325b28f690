//! What an elastic solid does at each stage of a step ([`BodyStages`], sec. 3.7): its rates
//! at the start positions and their update, its accelerations (eq. 30) with the external
//! acceleration the couplings add, and its shifting (eq. 36 or IPST), over its own
//! neighbour list ([`SolidSolid`](crate::solver::interactions::solid_solid::SolidSolid)) and
//! the other solids it sums its continuum equations over
//! ([`SolidContinuum`](crate::solver::interactions::solid_continuum::SolidContinuum)).

use super::{ElasticSolid, SolidRates};
use crate::solver::interactions::fluid_boundary::Boundaries;
use crate::solver::interactions::solid_continuum::Continuum;
use crate::solver::interactions::{Coupling, Interaction};
use crate::solver::nnps::Domain;
use crate::solver::passes::ipst::ipst_chi_reference;
use crate::solver::passes::solid::{self, SolidPasses};
use crate::solver::scheme::Shifting;
use crate::solver::systems::{Body, BodyStages, Rates, Work, World};

/// What a solid's passes keep between steps: which couplings they read and the passes'
/// work space (the gathered views, the free surface, IPST's).
#[derive(Debug)]
pub struct SolidWork<const D: usize> {
    /// The passes' work space.
    pub passes: SolidPasses<D>,
    /// The index of its own coupling among the couplings.
    own: usize,
    /// The indices of the solids' couplings it sums its continuum equations over.
    continuum: Vec<usize>,
    /// Whether any coupling adds an external acceleration to it.
    external: bool,
}

/// The stages of an [`ElasticSolid`].
pub struct SolidStages;

/// Body `i`, a solid, with its rates and work.
fn parts<'b, 'r, 'k, const D: usize>(
    bodies: &'b [Body<D>],
    rates: &'r mut [Rates<D>],
    work: &'k mut [Work<D>],
    i: usize,
) -> (&'b ElasticSolid<D>, &'r mut SolidRates<D>, &'k mut SolidWork<D>) {
    let (Body::ElasticSolid(s), Rates::Solid(r), Work::Solid(k)) = (&bodies[i], &mut rates[i], &mut work[i])
    else {
        unreachable!("a solid's rates and work are a solid's")
    };
    (s, r, k)
}

/// The own list of a solid whose work is `work`.
fn own<'a, const D: usize>(
    couplings: &'a [Coupling<D>],
    work: &SolidWork<D>,
) -> &'a crate::solver::interactions::lists::KernelList<D> {
    let Coupling::SolidSolid(c) = &couplings[work.own] else { unreachable!("a solid's own coupling") };
    &c.list
}

impl<const D: usize> BodyStages<D> for SolidStages {
    fn work(&self, _: &Body<D>, couplings: &[Coupling<D>], incoming: &[usize]) -> Work<D> {
        let of =
            |kind: Interaction| incoming.iter().copied().filter(move |&k| couplings[k].interaction() == kind);
        let own = of(Interaction::SolidSolid).next().expect("a solid's own coupling");
        let external = incoming
            .iter()
            .any(|&k| couplings[k].holds_force() || couplings[k].interaction() == Interaction::Load);
        Work::Solid(Box::new(SolidWork {
            passes: SolidPasses::default(),
            own,
            continuum: of(Interaction::SolidContinuum).collect(),
            external,
        }))
    }

    /// Wraps the positions into the box and bins them (a solid keeps its particles in the
    /// order given: no reordering).
    fn rebin(&self, w: &mut World<D>, i: usize) {
        let domain = w.domain;
        let solid = w.bodies[i].as_solid_mut().expect("a solid");
        solid.x.iter_mut().for_each(|x| domain.wrap(x));
        w.bins[i].update(&solid.x);
    }

    /// IPST's reference chi, if the solid shifts with it: the largest on its initial
    /// configuration (a solid always has a free surface, sec. 3.4).
    fn reference(&self, w: &mut World<D>, i: usize) {
        let World { bodies, work, couplings, kernel, .. } = w;
        let solid = bodies[i].as_solid().expect("a solid");
        if !matches!(solid.physics.ipst, Some(Shifting::Ipst { .. })) {
            return;
        }
        let work = work[i].as_solid().expect("a solid's work");
        let reference =
            ipst_chi_reference((&solid.x, solid.h), own(couplings, work), Boundaries::none(), kernel, true);
        let solid = bodies[i].as_solid_mut().expect("a solid");
        if let Some(Shifting::Ipst { chi_ref, .. }) = solid.physics.ipst.as_mut() {
            *chi_ref = reference;
        }
    }

    /// The external acceleration reset to its held part (the fluid's force on a structure),
    /// before the couplings at the solid's clock add theirs (a load).
    fn reset_external(&self, w: &mut World<D>, i: usize) {
        if !w.work[i].as_solid().expect("a solid's work").external {
            return;
        }
        let n = w.bodies[i].len();
        let Rates::Solid(r) = &mut w.rates[i] else { unreachable!("a solid's rates") };
        r.a_ext.clear();
        if r.a_held.is_empty() {
            r.a_ext.resize(n, crate::solver::math::Vector::zeros());
        } else {
            r.a_ext.extend_from_slice(&r.a_held);
        }
    }

    /// The views of its particles, and their kernel-gradient corrections if the scheme
    /// corrects the gradient (over the solids it sums across too, as they stand).
    fn gather(&self, w: &mut World<D>, i: usize) {
        let World { bodies, work, couplings, .. } = w;
        let solid = bodies[i].as_solid().expect("a solid");
        let mine = work[i].as_solid_mut().expect("a solid's work");
        mine.passes.gather(solid);
        let nl = own(couplings, mine);
        let SolidWork { passes, continuum, .. } = mine;
        solid::kernel_correction(passes, solid, nl, Continuum::sources(couplings, continuum, bodies));
    }

    /// The density, pressure and deviatoric-stress rates at the current positions and
    /// velocities (eqs. 25, 31, 32).
    fn start_rates(&self, w: &mut World<D>, i: usize, _: f64) {
        let World { bodies, rates, work, couplings, .. } = w;
        let Rates::Solid(r) = &mut rates[i] else { unreachable!("a solid's rates") };
        let solid = bodies[i].as_solid().expect("a solid");
        let mine = work[i].as_solid().expect("a solid's work");
        let continuum = Continuum::new(couplings, &mine.continuum, bodies, work);
        solid::density_and_stress_rates(&mine.passes, solid, own(couplings, mine), continuum, r);
    }

    /// Their update over `dt` (eqs. 56, 8, 58).
    fn start_update(&self, w: &mut World<D>, i: usize, dt: f64) {
        let (Body::ElasticSolid(solid), Rates::Solid(r)) = (&mut w.bodies[i], &w.rates[i]) else {
            unreachable!("a solid's rates are a solid's")
        };
        solid.update_state(r, dt);
    }

    /// Its free surface (sec. 3.4), if the scheme detects one.
    fn surface(&self, w: &mut World<D>, i: usize) -> bool {
        let World { bodies, work, couplings, .. } = w;
        let solid = bodies[i].as_solid().expect("a solid");
        let work = work[i].as_solid_mut().expect("a solid's work");
        let nl = own(couplings, work);
        solid::detect_surface(&mut work.passes, solid, nl);
        false
    }

    /// The accelerations (eq. 30) with the external acceleration, and Sun's shifting
    /// (eq. 36) or GTVF's background pressure (eq. 20) for a step `dt`.
    fn accelerations(&self, w: &mut World<D>, i: usize, dt: f64) {
        let World { bodies, rates, work, couplings, kernel, .. } = w;
        let Rates::Solid(r) = &mut rates[i] else { unreachable!("a solid's rates") };
        let solid = bodies[i].as_solid().expect("a solid");
        let mine = work[i].as_solid().expect("a solid's work");
        let continuum = Continuum::new(couplings, &mine.continuum, bodies, work);
        solid::accelerations(&mine.passes, solid, own(couplings, mine), continuum, r, (kernel, dt));
    }

    /// IPST's shifting (eqs. 37-41) over its own particles, if the scheme shifts with it.
    fn homogenise(&self, w: &mut World<D>, i: usize, dt: f64, next_step: u64) -> usize {
        let World { bodies, rates, work, couplings, bins, kernel, .. } = w;
        let (solid, r, mine) = parts(bodies, rates, work, i);
        let nl = own(couplings, mine);
        solid::homogenise(&mut mine.passes, solid, nl, &bins[i], kernel, r, dt, next_step)
    }

    /// Non-finite fields, a particle outside a bounded domain, a speed beyond `blowup`
    /// times the solid's speed of sound.
    fn check(&self, body: &Body<D>, domain: &Domain<D>, blowup: f64) -> Result<Option<f64>, String> {
        let s = body.as_solid().expect("a solid");
        let finite = |i: usize| {
            s.x[i].iter().chain(s.u[i].iter()).chain(s.s[i].iter()).all(|v| v.is_finite())
                && s.p[i].is_finite()
                && s.rho[i].is_finite()
        };
        if let Some(i) = (0..s.len()).find(|&i| !finite(i)) {
            return Err(format!("a field is not finite (particle {i} of solid `{}`)", s.name));
        }
        if let Some(i) = (0..s.len()).find(|&i| !domain.contains(&s.x[i])) {
            return Err(format!("particle {i} of solid `{}` left the domain", s.name));
        }
        let bound = blowup * s.material.c0();
        if s.max_speed() > bound {
            return Err(format!(
                "max |u| = {:.4e} of solid `{}` exceeds {blowup} c0 = {bound:.4e}",
                s.max_speed(),
                s.name,
            ));
        }
        Ok(None)
    }
}

impl<const D: usize> SolidWork<D> {
    /// Whether a coupling adds an external acceleration to the body.
    pub fn has_external(&self) -> bool {
        self.external
    }
}
