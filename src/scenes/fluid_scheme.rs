//! The scheme parameters every fluid scene declares, their checks by key, the time loop's
//! settings, and the fluid scheme built from them.

use super::params::{Bound, Params, Spec};
use crate::solver::integrator::{binding_limit, RatePositions, TimeStepLimit};
use crate::solver::kernel::{Kernel, KernelKind};
use crate::solver::scheme::{
    paper, Corrections, DensityModel, FluidScheme, FluidSettings, IpstTest, OptionError, PressureReference,
    Pst, SchemeName, SchemeOptions, SurfaceCone, SurfacePressure,
};
use crate::solver::simulation::TimeSettings;

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
