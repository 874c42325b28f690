//! What the fluid scenes share: the scheme parameters every fluid scene declares, the
//! scheme built from them, and the ParaView snapshots of fluid and wall bodies.

use super::params::{Bound, Params, Spec};
use crate::solver::integrator::{binding_limit, RatePositions, TimeStepLimit};
use crate::solver::kernel::{Kernel, KernelKind};
use crate::solver::math::Vector;
use crate::solver::output::vtu::{write_vtu, Field};
use crate::solver::scheme::{
    paper, Corrections, DensityModel, FluidScheme, FluidSettings, IpstTest, OptionError, PressureReference,
    Pst, SchemeName, SchemeOptions, SurfaceCone, SurfacePressure,
};
use crate::solver::simulation::{Builder, Simulation, TimeSettings};
use crate::solver::systems::{
    Body, ElasticSolid, Fluid, FluidInit, Wall, WallDensity, WallPressure, WallViscosity,
};
use std::path::Path;

const SWITCH: &[&str] = &["auto", "on", "off"];

/// The scheme parameters of a fluid scene (`pst` defaults to `default_pst`).
pub fn scheme_params(default_pst: &str) -> Vec<Spec> {
    vec![
        Spec::choice("scheme", SchemeName::NAMES, "ctvf", "fluid scheme"),
        Spec::choice("pst", Pst::NAMES, default_pst, "particle shifting for ctvf: Sun 2019, IPST or none"),
        Spec::choice("kernel", KernelKind::NAMES, "quintic_spline", "smoothing kernel"),
        Spec::float("hdx", 1.0, Bound::Positive, "h / dx"),
        Spec::choice("corrections", &["all", "none"], "all", "the CTVF correction terms, together"),
        Spec::choice(
            "corr_continuity",
            SWITCH,
            "auto",
            "the correction of eq. (25); auto follows `corrections`",
        ),
        Spec::choice(
            "corr_pressure",
            SWITCH,
            "auto",
            "the corrections of eq. (26); auto follows `corrections`",
        ),
        Spec::choice(
            "corr_momentum",
            SWITCH,
            "auto",
            "the -u div(u~ - u) term of eq. (19); auto follows `corrections`",
        ),
        Spec::choice(
            "pressure_reference",
            PressureReference::NAMES,
            "auto",
            "pressure subtracted in the pressure gradient: auto (the scheme's: the neighbour mean (BQL) for edac, and for ctvf in a periodic box), local_mean (BQL), global_mean (the fluid's mean) or none (eq. 27 as printed)",
        ),
        Spec::float("edac_alpha", paper::EDAC_ALPHA, Bound::Positive, "alpha of nu_edac, eq. (24)"),
        Spec::float(
            "ipst_tol",
            paper::IPST_TOL,
            Bound::Positive,
            "IPST tolerance on |max chi - chi_ref| / chi_ref, eq. (39)",
        ),
        // Bounded: a step's sweeps do not see Ctrl-C, and a tolerance no sweep meets would
        // otherwise make one step last forever.
        Spec::int("ipst_max_iter", paper::IPST_MAX_ITER as i64, 1, "IPST iterations per step at most")
            .at_most(1000.0),
        Spec::int(
            "ipst_interval",
            paper::IPST_INTERVAL as i64,
            1,
            "IPST on every this many steps, no homogenisation in between (the paper: 1; the authors' code: 5)",
        ),
        Spec::choice(
            "ipst_test",
            IpstTest::NAMES,
            "two_sided",
            "which deviation of the largest chi from its reference fails IPST's test, eq. (39): either (as printed) or only an excess",
        )
        .added_later(),
    ]
}

/// The parameters of a scene with a free surface (on top of [`scheme_params`]).
pub fn free_surface_params() -> Vec<Spec> {
    vec![
        Spec::choice(
            "surface_pressure",
            SurfacePressure::NAMES,
            "evolve",
            "pressure of the free-surface particles: evolved by eq. (26), held at 0 (p = p_atm), held at 0 where isolated, or evolved but not below 0",
        ),
        Spec::choice(
            "surface_cone",
            SurfaceCone::NAMES,
            "support",
            "neighbours of the 60-degree test of the free-surface detection: the whole support with the walls, or the fluid within 2h (the authors' code)",
        )
        .added_later(),
    ]
}

/// The simulation of scene `scene`: `bodies` in `domain` with `kernel`, its time loop as
/// the common parameters `p` set it ([`time_settings`]); an error names the scene.
pub fn simulation<const D: usize>(
    scene: &str,
    p: &Params,
    domain: crate::solver::nnps::Domain<D>,
    kernel: Kernel,
    bodies: impl IntoIterator<Item = Body<D>>,
) -> Result<Simulation<D>, String> {
    simulation_with(scene, p, domain, kernel, bodies, |b| b)
}

/// As [`simulation`], with what `pairs` sets for pairs of bodies on the builder (a pair kept
/// apart, two solids summing across, a load on a body).
pub fn simulation_with<const D: usize>(
    scene: &str,
    p: &Params,
    domain: crate::solver::nnps::Domain<D>,
    kernel: Kernel,
    bodies: impl IntoIterator<Item = Body<D>>,
    pairs: impl FnOnce(Builder<D>) -> Builder<D>,
) -> Result<Simulation<D>, String> {
    let builder = Simulation::builder(domain, kernel).time(time_settings(p));
    pairs(bodies.into_iter().fold(builder, |b, body| b.body(body)))
        .build()
        .map_err(|e| format!("scene `{scene}`: {e}"))
}

/// The time loop's settings from the common parameters (`cfl`, `rate_positions`).
pub fn time_settings(p: &Params) -> TimeSettings {
    TimeSettings {
        rate_positions: RatePositions::from_name(p.str("rate_positions")).expect("checked choice"),
        ..TimeSettings::new(p.float("cfl"))
    }
}

fn switch(p: &Params, key: &str, all: bool) -> bool {
    match p.str(key) {
        "on" => true,
        "off" => false,
        _ => all,
    }
}

/// The physical constants a scene gives its fluid.
pub struct FluidConstants {
    /// Reference density.
    pub rho0: f64,
    /// Speed of sound.
    pub c0: f64,
    /// Reference velocity.
    pub u_ref: f64,
    /// Particle spacing.
    pub dx: f64,
    /// Kinematic viscosity.
    pub nu: Option<f64>,
    /// Artificial viscosity alpha.
    pub alpha: Option<f64>,
    /// Density model.
    pub density: DensityModel,
    /// Gravity.
    pub gravity: [f64; 3],
    /// A free surface to detect and keep the shifting tangential to.
    pub free_surface: bool,
}

impl FluidConstants {
    /// An internal flow at Reynolds number `re` on velocity `u` and length `l`: viscosity
    /// `u l / re`, summation density, no gravity, no artificial viscosity, an arbitrary
    /// pressure level.
    pub fn internal_flow(rho0: f64, c0: f64, u: f64, l: f64, re: f64, dx: f64) -> Self {
        Self {
            rho0,
            c0,
            u_ref: u,
            dx,
            nu: Some(u * l / re),
            alpha: None,
            density: DensityModel::Summation,
            gravity: [0.0; 3],
            free_surface: false,
        }
    }

    /// Water of depth `height` under gravity `g` with a free surface: reference velocity
    /// `sqrt(2 g H)`, speed of sound ten times it, the continuity equation (25) for the
    /// density, artificial viscosity `alpha` (eq. 28) and no physical viscosity, in a tank
    /// (walls).
    pub fn under_gravity(rho0: f64, g: f64, height: f64, dx: f64, alpha: f64) -> Self {
        Self {
            rho0,
            c0: 10.0 * (2.0 * g * height).sqrt(),
            u_ref: (2.0 * g * height).sqrt(),
            dx,
            nu: None,
            alpha: Some(alpha),
            density: DensityModel::Continuity,
            gravity: [0.0, -g, 0.0],
            free_surface: true,
        }
    }
}

/// The scheme options of parameters `p` that were given (`given(key)`), typed for the
/// solver's check ([`SchemeOptions::check`]) with the scheme and shifting asked for; `None`
/// for a scene without scheme parameters. A value that switches an option off counts as
/// given, and passes the check.
pub fn scheme_options(p: &Params, given: impl Fn(&str) -> bool) -> Option<(SchemeName, Pst, SchemeOptions)> {
    let scheme = match p.0.get("scheme") {
        Some(super::params::Value::Str(s)) => SchemeName::from_name(s)?,
        _ => return None,
    };
    let pst = Pst::from_name(p.str("pst")).expect("checked choice");
    let on = |key: &str| given(key).then(|| p.str(key) == "on");
    let options = SchemeOptions {
        pst: given("pst").then_some(pst),
        corrections: given("corrections").then(|| p.str("corrections") == "all"),
        corr_continuity: on("corr_continuity"),
        corr_pressure: on("corr_pressure"),
        corr_momentum: on("corr_momentum"),
        ipst_tol: given("ipst_tol").then(|| p.float("ipst_tol")),
        ipst_max_iter: given("ipst_max_iter").then(|| p.int("ipst_max_iter") as usize),
        ipst_interval: given("ipst_interval").then(|| p.int("ipst_interval") as usize),
        ipst_test: given("ipst_test")
            .then(|| IpstTest::from_name(p.str("ipst_test")).expect("checked choice")),
        edac_alpha: given("edac_alpha").then(|| p.float("edac_alpha")),
    };
    Some((scheme, pst, options))
}

/// A scheme option of `p` given (`given(key)`) for a scheme that does not read it, as the
/// solver's typed settings find it: such a value would be ignored without a word.
pub fn unused_scheme_option(p: &Params, given: impl Fn(&str) -> bool) -> Option<OptionError> {
    let (scheme, pst, options) = scheme_options(p, given)?;
    options.check(scheme, pst).err()
}

/// Refuses the internal-flow schemes for a scene with a free surface.
pub fn require_free_surface_scheme(scene: &str, p: &Params) -> Result<(), String> {
    if p.str("scheme") == "ctvf" {
        return Ok(());
    }
    Err(format!(
        "scene `{scene}`: `scheme` = {}: a free-surface flow needs ctvf (edac and tvf are internal-flow schemes)",
        p.str("scheme")
    ))
}

/// Steps a run may need at its first time step: a billion steps of the smallest scene
/// would take days; the paper preset's longest run takes 5e5.
const MAX_STEPS: f64 = 1e9;

/// Parameters that shrink the time step of eq. (61) without bound (`re` = 1e-30 is > 0)
/// would step forever: refuse, before anything runs, a run needing more steps than any
/// machine takes, naming the limit that binds.
fn check_step_count(scene: &str, p: &Params, h: f64, c: &FluidConstants) -> Result<(), String> {
    let g = c.gravity.iter().map(|v| v * v).sum::<f64>().sqrt();
    let (limit, dt) = binding_limit(p.float("cfl"), h, c.c0, c.u_ref, c.nu, g);
    let tf = p.float("tf");
    let steps = tf / dt;
    if steps > MAX_STEPS {
        return Err(format!(
            "scene `{scene}`: `tf` = {tf} s needs {steps:.1e} steps at the time step of eq. (61), {dt:.3e} s (its {} limit at `cfl` = {}), more than {MAX_STEPS:.0e}: check {}",
            limit.name(),
            p.float("cfl"),
            match limit {
                TimeStepLimit::Viscous => "the viscosity (re)",
                TimeStepLimit::BodyForce => "gravity",
                TimeStepLimit::Acoustic => "the resolution and the speed of sound",
            }
        ));
    }
    Ok(())
}

/// The kernel (normalised in `D` dimensions), smoothing length and scheme the parameters
/// ask for. A support that does not reach the nearest particle (`support * hdx <= 1`) is
/// refused: the particles would have no neighbours, and Sun's shifting divides by W(dx) = 0.
/// So is a run whose time step would need more than `MAX_STEPS` steps.
pub fn fluid_scheme<const D: usize>(
    scene: &str,
    p: &Params,
    c: &FluidConstants,
) -> Result<(Kernel, f64, FluidScheme), String> {
    let hdx = p.float("hdx");
    let h = hdx * c.dx;
    let kernel = Kernel::new(KernelKind::from_name(p.str("kernel")).expect("checked choice"), D);
    if kernel.support() * hdx <= 1.0 {
        return Err(format!(
            "scene `{scene}`: `hdx` = {hdx}: the {} support ({} h = {:.3} dx) does not reach the nearest particle at dx; use hdx > {:.4}",
            p.str("kernel"),
            kernel.support(),
            kernel.support() * hdx,
            1.0 / kernel.support()
        ));
    }
    check_step_count(scene, p, h, c)?;
    let all = p.str("corrections") == "all";
    let corrections = Corrections {
        continuity: switch(p, "corr_continuity", all),
        pressure: switch(p, "corr_pressure", all),
        momentum: switch(p, "corr_momentum", all),
    };
    let settings = FluidSettings {
        rho0: c.rho0,
        c0: c.c0,
        u_ref: c.u_ref,
        h,
        w_dx: kernel.w(c.dx, h),
        nu: c.nu,
        alpha: c.alpha,
        edac_alpha: p.float("edac_alpha"),
        density: c.density,
        pst: Pst::from_name(p.str("pst")).expect("checked choice"),
        corrections,
        ipst_tol: p.float("ipst_tol"),
        ipst_max_iter: p.int("ipst_max_iter") as usize,
        ipst_interval: p.int("ipst_interval") as usize,
        gravity: c.gravity,
        pressure_reference: PressureReference::from_name(p.str("pressure_reference"))
            .expect("checked choice"),
        free_surface: c.free_surface.then(|| {
            SurfacePressure::from_name(p.str("surface_pressure"))
                .expect("checked choice (free_surface_params)")
        }),
        surface_cone: match p.0.get("surface_cone") {
            Some(_) => SurfaceCone::from_name(p.str("surface_cone")).expect("checked choice"),
            None => SurfaceCone::default(),
        },
        ipst_test: IpstTest::from_name(p.str("ipst_test")).expect("checked choice"),
    };
    let scheme = SchemeName::from_name(p.str("scheme")).expect("checked choice").fluid_scheme(&settings);
    Ok((kernel, h, scheme))
}

/// Bytes a particle takes at most in `D` dimensions, with its neighbour list and every
/// scheme's work arrays: in 2D `sphrepro bench` measures 860-1940 (the most at nx = 50, where
/// fixed costs weigh); in 3D, with four times the neighbours, the peak resident size of a
/// 40x40x8 Taylor-Green run is 3.5 kB a particle with SPST and 3.8 kB with IPST.
const fn bytes_per_particle(d: usize) -> f64 {
    if d < 3 {
        2048.0
    } else {
        4096.0
    }
}

/// Refuses a resolution (parameter `key` = `value`) whose `particles` could not run: more
/// than the neighbour lists' 32-bit indices hold, or more memory than this machine has
/// (see `total_memory`). Called before any particle is made, so that a mistyped resolution
/// is a parameter error, not minutes of allocation ending in an abort.
pub fn check_size<const D: usize>(
    scene: &str,
    key: &str,
    value: impl std::fmt::Display,
    particles: f64,
) -> Result<(), String> {
    let refuse =
        |why: String| Err(format!("scene `{scene}`: `{key}` = {value}: {particles:.3e} particles {why}"));
    if particles > u32::MAX as f64 {
        return refuse(format!("are more than the {} a neighbour list indexes", u32::MAX));
    }
    let need = particles * bytes_per_particle(D);
    match total_memory() {
        Some(have) if need > have => refuse(format!(
            "need about {:.1} GiB, more than this machine's {:.1} GiB",
            need / GIB,
            have / GIB
        )),
        _ => Ok(()),
    }
}

const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

/// The memory this process may use in bytes, if the system says (Linux): the machine's
/// physical memory, or a container's limit (cgroup v2) if lower, or what its address-space
/// limit (`ulimit -v`) leaves beyond the address space it already holds, if lower still (an
/// allocation past that limit aborts the process, with no summary).
fn total_memory() -> Option<f64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemTotal:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    let limit =
        std::fs::read_to_string("/sys/fs/cgroup/memory.max").ok().and_then(|s| s.trim().parse::<f64>().ok());
    let have = limit.map_or(kib * 1024.0, |l| l.min(kib * 1024.0));
    Some(address_space_left().map_or(have, |left| left.min(have)))
}

/// Bytes of address space left under the process's limit (`RLIMIT_AS`), if it has one.
#[cfg(target_os = "linux")]
fn address_space_left() -> Option<f64> {
    let mut limit = libc::rlimit { rlim_cur: 0, rlim_max: 0 };
    // SAFETY: getrlimit writes into the struct it is given.
    if unsafe { libc::getrlimit(libc::RLIMIT_AS, &mut limit) } != 0 || limit.rlim_cur == libc::RLIM_INFINITY {
        return None;
    }
    // VmSize: the address space the process holds now, in kiB.
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmSize:"))?;
    let held: f64 = line.split_whitespace().nth(1)?.parse::<f64>().ok()? * 1024.0;
    Some((limit.rlim_cur as f64 - held).max(0.0))
}

#[cfg(not(target_os = "linux"))]
fn address_space_left() -> Option<f64> {
    None
}

/// A `D`-vector as the three components ParaView reads (zeros beyond `D`).
fn pad<const D: usize>(v: &Vector<D>) -> [f64; 3] {
    std::array::from_fn(|k| if k < D { v[k] } else { 0.0 })
}

/// Writes a fluid snapshot with velocity, speed, pressure, density, id and the `extra`
/// fields (one value per particle of the fluid); of the particles whose original index is in
/// `ids` only, if given (one part of the fluid).
pub fn write_fluid<const D: usize>(
    path: &Path,
    f: &Fluid<D>,
    extra: &[Field],
    ids: Option<&std::ops::Range<u32>>,
) -> std::io::Result<()> {
    let mut fields = vec![
        Field::Vector("velocity", f.u.iter().map(pad).collect()),
        Field::Scalar("speed", f.u.iter().map(|u| u.norm()).collect()),
        Field::Scalar("pressure", f.p.clone()),
        Field::Scalar("density", f.rho.clone()),
        Field::Int("id", f.id.iter().map(|&i| i as i64).collect()),
    ];
    fields.extend(extra.iter().cloned());
    let x: Vec<[f64; 3]> = f.x.iter().map(pad).collect();
    match ids {
        None => write_vtu(path, &x, &fields),
        Some(ids) => {
            let keep: Vec<usize> = (0..f.len()).filter(|&k| ids.contains(&f.id[k])).collect();
            let fields: Vec<Field> = fields.iter().map(|field| field.select(&keep)).collect();
            write_vtu(path, &keep.iter().map(|&k| x[k]).collect::<Vec<_>>(), &fields)
        }
    }
}

/// The shifting's time-series columns, every scene alike: IPST's moves in the last step
/// (0 without IPST) and the largest shifting speed |u~ - u| (0 without shifting).
pub fn shifting_columns<const D: usize>(sim: &Simulation<D>) -> [(&'static str, f64); 2] {
    let shift_max = sim.shift_speeds().map_or(0.0, |s| s.into_iter().fold(0.0, f64::max));
    [("ipst_iterations", sim.last_ipst_iterations() as f64), ("shift_max", shift_max)]
}

/// Where the scheme moves the particles with a transport velocity u~ (CTVF eq. 33): u~ and
/// the shifting speed of the coming step, |u~ - u| (see [`Simulation::shift_speeds`]), as
/// snapshot fields; nothing otherwise.
pub fn shifting_fields<const D: usize>(sim: &Simulation<D>) -> Vec<Field<'static>> {
    if !sim.has_fluid() {
        return Vec::new();
    }
    match (&sim.fluid().u_hat, sim.shift_speeds()) {
        (Some(u_hat), Some(shift)) => vec![
            Field::Vector("transport_velocity", u_hat.iter().map(pad).collect()),
            Field::Scalar("shift_speed", shift),
        ],
        _ => Vec::new(),
    }
}

/// Free-surface snapshot fields of `sim`: normal, surface and near-surface flags.
pub fn surface_fields<const D: usize>(sim: &Simulation<D>) -> Vec<Field<'static>> {
    let Some(fs) = sim.surface() else { return Vec::new() };
    vec![
        Field::Vector("normal", fs.normal.iter().map(pad).collect()),
        Field::Int("free_surface", fs.surface.iter().map(|&s| s as i64).collect()),
        Field::Int("near_surface", fs.near.iter().map(|&s| s as i64).collect()),
    ]
}

/// Writes a wall snapshot: prescribed velocity, extrapolated pressure and density, normal.
pub fn write_wall<const D: usize>(path: &Path, w: &Wall<D>) -> std::io::Result<()> {
    let u: Vec<Vector<D>> = (0..w.len()).map(|i| w.velocity(i)).collect();
    write_vtu(
        path,
        &w.x.iter().map(pad).collect::<Vec<_>>(),
        &[
            Field::Vector("velocity", u.iter().map(pad).collect()),
            Field::Scalar("speed", u.iter().map(|u| u.norm()).collect()),
            Field::Scalar("pressure", w.boundary.ghost.iter().map(|g| g.p).collect()),
            Field::Scalar("density", w.boundary.rho.clone()),
            Field::Vector("normal", w.normal.iter().map(pad).collect()),
        ],
    )
}

/// Writes an elastic solid's snapshot: velocity, speed, pressure, density, deviatoric
/// stress (its components and von Mises' `sqrt(3 J2)`), the fixed flag, and its free
/// surface if detected.
pub fn write_solid<const D: usize>(
    path: &Path,
    s: &ElasticSolid<D>,
    surface: Option<&crate::solver::passes::free_surface::SurfaceFields<D>>,
) -> std::io::Result<()> {
    use crate::solver::equations::solid::j2;
    let mut fields = vec![
        Field::Vector("velocity", s.u.iter().map(pad).collect()),
        Field::Scalar("speed", s.u.iter().map(|u| u.norm()).collect()),
        Field::Scalar("pressure", s.p.clone()),
        Field::Scalar("density", s.rho.clone()),
        Field::Scalar("von_mises", s.s.iter().map(|m| (3.0 * j2(m)).sqrt()).collect()),
        Field::Int("fixed", s.fixed.iter().map(|&f| f as i64).collect()),
    ];
    for (name, (i, j)) in [("s00", (0, 0)), ("s01", (0, 1)), ("s11", (1, 1))] {
        if i < D && j < D {
            fields.push(Field::Scalar(name, s.s.iter().map(|m| m[(i, j)]).collect()));
        }
    }
    if let Some(fs) = surface {
        fields.push(Field::Int("free_surface", fs.surface.iter().map(|&f| f as i64).collect()));
    }
    write_vtu(path, &s.x.iter().map(pad).collect::<Vec<_>>(), &fields)
}

/// Shepard interpolation of `value` (per fluid particle) at `q`: `sum v W / sum W`, by
/// brute force over the particles (for a handful of probe points at the end of a run).
pub fn shepard(f: &Fluid<2>, kernel: &Kernel, q: Vector<2>, value: impl Fn(usize) -> f64) -> Option<f64> {
    let k = kernel.scaled(f.h);
    let r2max = (kernel.support() * f.h).powi(2);
    let (mut num, mut den) = (0.0, 0.0);
    for j in 0..f.len() {
        let r2 = (q - f.x[j]).norm_squared();
        if r2 < r2max {
            let w = k.w(r2.sqrt());
            num += value(j) * w;
            den += w;
        }
    }
    (den > 0.0).then(|| num / den)
}

/// The [`SceneRun`](super::SceneRun) counts every scene forwards to its `sim` field
/// (a `Simulation<D>`): particles, time, steps.
macro_rules! forward_counts {
    () => {
        fn particles(&self) -> usize {
            $crate::scenes::common::particle_count(&self.sim)
        }
        fn body_particles(&self) -> Vec<(String, usize)> {
            $crate::scenes::common::body_particles(&self.sim)
        }
        fn time(&self) -> f64 {
            self.sim.time()
        }
        fn steps(&self) -> u64 {
            self.sim.steps()
        }
        fn wavefront_steps(&self) -> u64 {
            self.sim.wavefront_steps()
        }
    };
}
pub(crate) use forward_counts;

/// The counts of [`forward_counts`] and an advance that is `Simulation::advance`'s.
macro_rules! forward_to_sim {
    () => {
        $crate::scenes::common::forward_counts!();
        fn advance(
            &mut self,
            t_stop: f64,
            t_end: f64,
            on_step: &mut dyn FnMut(f64, u64) -> bool,
        ) -> Result<bool, $crate::solver::simulation::Divergence> {
            self.sim.advance(t_stop, t_end, |s| on_step(s.time(), s.steps()))
        }
    };
}
pub(crate) use forward_to_sim;

/// The plan written at the top of a run log: the bodies (with `setting`, e.g. the walls'
/// layout), the kernel and the fluid's scheme with every term it evaluates.
pub fn plan<const D: usize>(sim: &Simulation<D>, setting: &str) -> String {
    let mut bodies = Vec::new();
    for body in sim.bodies() {
        match body {
            Body::Fluid(f) => {
                for part in &f.parts {
                    bodies.push(format!(
                        "body `{}`: {} particles, h = {:.4e}",
                        part.name,
                        part.ids.len(),
                        f.h
                    ));
                }
            }
            Body::Wall(w) => bodies.push(format!("body `{}`: {} particles", w.name, w.len())),
            Body::ElasticSolid(s) => bodies.push(format!(
                "body `{}`: {} particles ({} fixed), h = {:.4e}, E = {:.4e} Pa, nu = {}, rho0 = {}, c0 = {:.4e} m/s",
                s.name,
                s.len(),
                s.fixed.iter().filter(|&&f| f).count(),
                s.h,
                s.material.youngs_modulus,
                s.material.poisson_ratio,
                s.material.rho0,
                s.material.c0()
            )),
        }
    }
    let mut schemes: Vec<String> = sim.solids().map(|s| format!("{}", s.physics)).collect();
    if sim.has_fluid() {
        schemes.insert(0, format!("{}", sim.fluid().physics));
    }
    format!("{}, kernel {:?} ({setting})\n{}", bodies.join("; "), sim.kernel.kind(), schemes.join("\n"))
}

/// The particles of each body of `sim` (each part of the fluid apart), by name.
pub fn body_particles<const D: usize>(sim: &Simulation<D>) -> Vec<(String, usize)> {
    let mut out = Vec::new();
    for body in sim.bodies() {
        match body {
            Body::Fluid(f) => out.extend(f.parts.iter().map(|p| (p.name.clone(), p.ids.len()))),
            Body::Wall(w) => out.push((w.name.clone(), w.len())),
            Body::ElasticSolid(s) => out.push((s.name.clone(), s.len())),
        }
    }
    out
}

/// Particles in every body of `sim`.
pub fn particle_count<const D: usize>(sim: &Simulation<D>) -> usize {
    sim.bodies().iter().map(Body::len).sum()
}

/// Writes the snapshots of every body of `sim` (each part of the fluid with `extra` fields)
/// for output number `index`; returns the (body, file) pairs.
pub fn snapshot_bodies<const D: usize>(
    sim: &Simulation<D>,
    dir: &Path,
    index: usize,
    extra: Vec<Field>,
) -> std::io::Result<Vec<(String, String)>> {
    let mut fields = shifting_fields(sim);
    fields.extend(extra);
    let mut files = Vec::new();
    for body in sim.bodies() {
        match body {
            Body::Fluid(f) => {
                let whole = f.parts.len() == 1;
                for part in &f.parts {
                    let name = format!("{}_{index:05}.vtu", part.name);
                    write_fluid(&dir.join(&name), f, &fields, (!whole).then_some(&part.ids))?;
                    files.push((part.name.clone(), name));
                }
            }
            Body::Wall(w) => {
                let name = format!("{}_{index:05}.vtu", w.name);
                write_wall(&dir.join(&name), w)?;
                files.push((w.name.clone(), name));
            }
            Body::ElasticSolid(s) => {
                let name = format!("{}_{index:05}.vtu", s.name);
                write_solid(&dir.join(&name), s, sim.solid_surface(&s.name))?;
                files.push((s.name.clone(), name));
            }
        }
    }
    Ok(files)
}

/// Restores `sim` from the `sim` entry of a scene's checkpoint.
pub fn restore_sim<const D: usize>(sim: &mut Simulation<D>, state: &serde_json::Value) -> Result<(), String> {
    sim.restore(serde_json::from_value(state["sim"].clone()).map_err(|e| format!("checkpoint: {e}"))?);
    Ok(())
}

/// Refuses a kernel whose support reaches past `layers` wall layers of spacing `dx`.
pub fn check_wall_layers(
    scene: &str,
    p: &Params,
    kernel: &Kernel,
    h: f64,
    dx: f64,
    layers: usize,
) -> Result<(), String> {
    if kernel.support() * h > layers as f64 * dx + 1e-12 {
        return Err(format!(
            "scene `{scene}`: kernel support {:.3} dx exceeds the {layers} wall layers: lower `hdx` (= {})",
            kernel.support() * h / dx,
            p.float("hdx")
        ));
    }
    Ok(())
}

/// A fluid of `physics` at rest on the points `x` (spacing `dx`, density `rho0`) with
/// pressure `p(x)`.
pub fn fluid_at_rest(
    x: Vec<Vector<2>>,
    dx: f64,
    rho0: f64,
    h: f64,
    physics: FluidScheme,
    p: impl Fn(&Vector<2>) -> f64,
) -> Result<Fluid<2>, String> {
    let n = x.len();
    let init = FluidInit {
        u: vec![Vector::zeros(); n],
        m: vec![rho0 * dx * dx; n],
        rho: vec![rho0; n],
        p: x.iter().map(p).collect(),
        x,
    };
    Fluid::new("fluid", h, init, physics)
}

/// A wall body from (position, normal) pairs with prescribed velocity `u(x)`.
pub fn wall_from(
    particles: &[(Vector<2>, Vector<2>)],
    u: impl Fn(&Vector<2>) -> Vector<2>,
    dx: f64,
    rho0: f64,
    c0: f64,
) -> Result<Wall<2>, String> {
    Wall::new(
        "wall",
        particles.iter().map(|w| w.0).collect(),
        particles.iter().map(|w| u(&w.0)).collect(),
        particles.iter().map(|w| w.1).collect(),
        rho0 * dx * dx,
        rho0,
        c0,
    )
}

/// The wall density the parameters ask for (see [`wall_params`]).
pub fn wall_density(p: &Params) -> WallDensity {
    WallDensity::from_name(p.str("wall_density")).expect("checked choice (wall_params)")
}

/// The wall pressure the parameters ask for (see [`wall_params`]).
pub fn wall_pressure(p: &Params) -> WallPressure {
    WallPressure::from_name(p.str("wall_pressure")).expect("checked choice (wall_params)")
}

/// The velocity the walls present to the artificial viscosity (see [`wall_params`]).
pub fn wall_viscosity(p: &Params) -> WallViscosity {
    WallViscosity::from_name(p.str("wall_viscosity")).expect("checked choice (wall_params)")
}

/// The parameters of a scene with walls.
pub fn wall_params() -> Vec<Spec> {
    vec![
        Spec::choice(
            "wall_density",
            WallDensity::NAMES,
            "state_equation",
            "density of the wall particles: from their extrapolated pressure by the linear state equation (Adami 2012), or the reference density (PySPH's EDAC walls)",
        ),
        Spec::choice(
            "wall_pressure",
            WallPressure::NAMES,
            "extrapolated",
            "pressure of the wall particles: eq. (52) as it stands, or clamped at zero so that walls never pull the fluid (PySPH's ClampWallPressure)",
        )
        .added_later(),
        Spec::choice(
            "wall_viscosity",
            WallViscosity::NAMES,
            "no_slip",
            "velocity the artificial viscosity sees on a wall: the no-slip ghost velocity of eq. (50), or the wall's own (PySPH, the authors' code)",
        )
        .added_later(),
    ]
}

/// The RMS deviation of a sampled curve `ours` (time, value; in time order) from the points
/// `reference` within its time range: ours interpolated linearly at each reference time
/// (the first sample's value before it); reference points after our last sample are
/// skipped. `None` when no reference point falls in range.
pub fn rms_deviation(ours: &[(f64, f64)], reference: &[(f64, f64)]) -> Option<f64> {
    let (mut sum2, mut n) = (0.0, 0);
    for &(ts, z) in reference {
        let Some(i) = ours.iter().position(|&(t, _)| t >= ts) else { continue };
        let value = if i == 0 {
            ours[0].1
        } else {
            let ((t0, z0), (t1, z1)) = (ours[i - 1], ours[i]);
            z0 + (z1 - z0) * (ts - t0) / (t1 - t0).max(1e-300)
        };
        sum2 += (value - z).powi(2);
        n += 1;
    }
    (n > 0).then(|| (sum2 / n as f64).sqrt())
}
