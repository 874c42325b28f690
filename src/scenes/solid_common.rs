//! What the elastic-solid scenes share: the material and scheme parameters every one of
//! them takes (`dx`, `hdx`, `youngs_modulus`, `poisson_ratio`, `density`, `yield_stress`
//! where plastic, `alpha`, `scheme`, `pst`, `corrections`), their checks by key before any
//! particle is made, and the [`SolidSetup`] they give (with a rectangular block's,
//! [`BlockSetup`]); plus a point of a solid followed over a run ([`Probe`]) and the extremum
//! detector that reads an oscillation from it ([`Extrema`]).

use super::params::{Bound, Params, Spec};
use crate::solver::kernel::{Kernel, KernelKind};
use crate::solver::math::Vector;
use crate::solver::scheme::{Pst, SolidGradient, SolidScheme, SolidSchemeName, SolidSettings, SurfaceShift};
use crate::solver::systems::{ElasticSolid, SolidMaterial};
use serde::{Deserialize, Serialize};

/// The most steps a run may need (as the fluid scenes' bound).
pub const MAX_STEPS: f64 = 1e9;

/// A solid scene's defaults: the paper's case.
#[derive(Clone, Copy, Debug)]
pub struct SolidDefaults {
    /// Particle spacing (m).
    pub dx: f64,
    /// Young's modulus (Pa).
    pub youngs_modulus: f64,
    /// Poisson's ratio.
    pub poisson_ratio: f64,
    /// Reference density (kg/m^3).
    pub density: f64,
    /// The yield stress Y0 (Pa) of an elastic-perfectly-plastic material; `None`: elastic,
    /// and the scene has no `yield_stress` parameter.
    pub yield_stress: Option<f64>,
    /// Artificial viscosity alpha of eq. (28).
    pub alpha: f64,
    /// The default shifting.
    pub pst: &'static str,
}

/// The names a solid's parameters go by: a solid scene's own, or those of a structure in a
/// fluid, whose scheme takes the plain names ([`STRUCTURE`]).
#[derive(Clone, Copy, Debug)]
pub struct SolidKeys {
    /// Whether the solid declares the spacing `dx` and `hdx` (a structure shares the
    /// fluid's).
    pub own_spacing: bool,
    /// Reference density.
    pub density: &'static str,
    /// Artificial viscosity alpha.
    pub alpha: &'static str,
    /// The scheme.
    pub scheme: &'static str,
    /// The shifting.
    pub pst: &'static str,
    /// The correction terms.
    pub corrections: &'static str,
    /// The kernel gradient: the paper's or corrected.
    pub gradient: &'static str,
    /// GTVF's background-pressure cap.
    pub gtvf_p_ref: &'static str,
    /// How the shift is kept from the free surface.
    pub surface_shift: &'static str,
}

/// A solid scene's parameter names.
pub const SOLID: SolidKeys = SolidKeys {
    own_spacing: true,
    density: "density",
    alpha: "alpha",
    scheme: "scheme",
    pst: "pst",
    corrections: "corrections",
    gradient: "gradient",
    gtvf_p_ref: "gtvf_p_ref",
    surface_shift: "surface_shift",
};

/// The parameter names of a structure in a fluid: prefixed `solid_` where the fluid's
/// scheme takes the plain name.
pub const STRUCTURE: SolidKeys = SolidKeys {
    own_spacing: false,
    density: "solid_density",
    alpha: "solid_alpha",
    scheme: "solid_scheme",
    pst: "solid_pst",
    corrections: "solid_corrections",
    gradient: "solid_gradient",
    gtvf_p_ref: "solid_gtvf_p_ref",
    surface_shift: "solid_surface_shift",
};

/// The shifting choices of a solid.
pub const SOLID_PST: &[&str] = &["sun", "ipst", "none"];

/// The parameters of a solid scene with defaults `d` (the scene's own come before them and
/// the common ones after).
pub fn solid_params(d: &SolidDefaults) -> Vec<Spec> {
    solid_params_as(d, &SOLID)
}

/// The parameters of a solid with defaults `d` under the names `k` (without the spacing for
/// a structure: `d.dx` is then unused).
pub fn solid_params_as(d: &SolidDefaults, k: &SolidKeys) -> Vec<Spec> {
    let mut v = Vec::new();
    if k.own_spacing {
        v.extend([
            Spec::float("dx", d.dx, Bound::Positive, "particle spacing (m)"),
            Spec::float("hdx", 1.0, Bound::Positive, "h / dx"),
        ]);
    }
    v.extend([
        Spec::float("youngs_modulus", d.youngs_modulus, Bound::Positive, "Young's modulus E (Pa)"),
        Spec::float("poisson_ratio", d.poisson_ratio, Bound::None, "Poisson's ratio nu, in (-1, 0.5)"),
        Spec::float(k.density, d.density, Bound::Positive, "reference density rho0 (kg/m^3)"),
    ]);
    if let Some(y0) = d.yield_stress {
        v.push(Spec::float(
            "yield_stress",
            y0,
            Bound::Positive,
            "yield stress Y0 (Pa) of the elastic-perfectly-plastic material (sec. 4.7)",
        ));
    }
    v.extend([
        Spec::float(k.alpha, d.alpha, Bound::NonNegative, "artificial viscosity alpha, eq. (28)"),
        Spec::choice(
            k.scheme,
            SolidSchemeName::NAMES,
            "ctvf",
            "solid scheme: ctvf (eq. 31 of u, corrections), gtvf_pst (of u~, no corrections, shifted by pst), gtvf (the same homogenised by GTVF's background pressure; pst = none) or gray (no transport velocity, Monaghan's artificial stress; pst = none)",
        ),
        Spec::choice(
            k.pst,
            SOLID_PST,
            d.pst,
            "particle shifting: Sun 2019 (eq. 36), IPST (sec. 3.3) or none (gray and gtvf: none)",
        ),
        Spec::choice(
            k.corrections,
            &["all", "none"],
            "all",
            "the CTVF correction terms of eqs. (25) and (32) (ctvf)",
        ),
        Spec::choice(
            k.gradient,
            SolidGradient::NAMES,
            "paper",
            "the solid's kernel gradient: the paper's, or corrected by L = (sum V_b grad W (x) x_ba)^-1 (Bonet & Lok; beyond the paper)",
        )
        .added_later(),
        Spec::float(
            k.gtvf_p_ref,
            0.0,
            Bound::NonNegative,
            "cap p_ref of GTVF's background pressure p0 = min(10 |p|, p_ref) (Pa; gtvf only); 0: the bulk modulus, as the authors' code",
        )
        .added_later(),
        Spec::choice(
            k.surface_shift,
            SurfaceShift::NAMES,
            "normal",
            "near the free surface the shift loses its normal component (normal, eq. 44 as printed) or only an outward one (outward, the authors' code)",
        )
        .added_later(),
    ]);
    v
}

/// What a solid scene's parameters make, once every check that needs no particle passed.
#[derive(Clone, Debug)]
pub struct SolidSetup {
    /// The material.
    pub material: SolidMaterial,
    /// The solid's scheme.
    pub scheme: SolidScheme,
    /// The kernel (quintic spline, as the paper's solids).
    pub kernel: Kernel,
    /// Particle spacing.
    pub dx: f64,
    /// Smoothing length `hdx dx`.
    pub h: f64,
}

impl SolidSetup {
    /// Kernel support layers of spacing `dx`: how deep a clamp must be.
    pub fn support_layers(&self) -> usize {
        (self.kernel.support() * self.h / self.dx).ceil() as usize
    }
}

/// The setup of scene `scene` from `p`: the material (refused by key: `poisson_ratio`
/// outside (-1, 0.5), `hdx` outside [0.5, 3]), the scheme, and a check that `tf` needs no
/// more than [`MAX_STEPS`] steps of eq. (62) at the largest speed `u_max` the scene
/// expects, which the parameters `u_keys` (e.g. "`v0`") set. `u_ref` is the reference speed
/// of Sun's shifting (eq. 36).
pub fn solid_setup(
    scene: &str,
    p: &Params,
    u_max: (f64, &str),
    u_ref: f64,
    gravity: [f64; 3],
) -> Result<SolidSetup, String> {
    solid_setup_as(scene, p, &SOLID, u_max, (u_ref, gravity))
}

/// As [`solid_setup`] for the parameters named `k`.
pub fn solid_setup_as(
    scene: &str,
    p: &Params,
    k: &SolidKeys,
    (u_max, u_keys): (f64, &str),
    (u_ref, gravity): (f64, [f64; 3]),
) -> Result<SolidSetup, String> {
    let bad =
        |key: &str, why: &str| Err(format!("scene `{scene}`: parameter `{key}` = {:?}: {why}", p.float(key)));
    let nu = p.float("poisson_ratio");
    if !(nu > -1.0 && nu < 0.5) {
        return bad(
            "poisson_ratio",
            "must lie in (-1, 0.5): at 0.5 the bulk modulus is infinite, at -1 the shear modulus",
        );
    }
    let hdx = p.float("hdx");
    if !(0.5..=3.0).contains(&hdx) {
        return bad("hdx", "must lie in [0.5, 3]: the kernel must reach the nearest particles");
    }
    let mut material = SolidMaterial::new(p.float("youngs_modulus"), nu, p.float(k.density))
        .map_err(|e| format!("scene `{scene}`: {e}"))?;
    if p.0.contains_key("yield_stress") {
        material = material
            .with_yield_stress(p.float("yield_stress"))
            .map_err(|e| format!("scene `{scene}`: {e}"))?;
    }
    let dx = p.float("dx");
    let kernel = Kernel::new(KernelKind::QuinticSpline, 2);
    let h = hdx * dx;
    // Eq. (62) at the largest expected speed: a run of more steps than any machine takes
    // is refused.
    let dt = p.float("cfl") * h / (material.c0() + u_max);
    let steps = p.float("tf") / dt;
    if steps.is_nan() || steps > MAX_STEPS {
        return Err(format!(
            "scene `{scene}`: `tf` = {:?} needs {steps:.3e} steps of eq. (62), dt = `cfl` h / (c0 + |u|) = {dt:.3e} s with c0 = {:.3e} m/s from `youngs_modulus`, `poisson_ratio` and `{}`, |u| = {u_max:.3e} m/s from {u_keys}, h = `hdx` `dx`: more than {MAX_STEPS:e}",
            p.float("tf"),
            material.c0(),
            k.density
        ));
    }
    let pst = Pst::from_name(p.str(k.pst)).expect("checked choice");
    let name = SolidSchemeName::from_name(p.str(k.scheme)).expect("checked choice");
    if p.str(k.surface_shift) != "normal" && pst == Pst::None {
        return Err(format!(
            "scene `{scene}`: parameter `{}` = {}: only a shifting technique reads it, not `{}` = none",
            k.surface_shift,
            p.str(k.surface_shift),
            k.pst
        ));
    }
    let settings = SolidSettings {
        pst,
        corrections: p.str(k.corrections) == "all",
        alpha: p.float(k.alpha),
        u_ref,
        w_dx: kernel.w(dx, h),
        gravity,
        gradient: SolidGradient::from_name(p.str(k.gradient)).expect("checked choice"),
        surface_shift: SurfaceShift::from_name(p.str(k.surface_shift)).expect("checked choice"),
        p_ref: match p.float(k.gtvf_p_ref) {
            0.0 => material.bulk_modulus(),
            p_ref if name == SolidSchemeName::Gtvf => p_ref,
            p_ref => {
                return Err(format!(
                    "scene `{scene}`: parameter `{}` = {p_ref:?}: only `{}` = gtvf reads it, not `{}` = {}",
                    k.gtvf_p_ref,
                    k.scheme,
                    k.scheme,
                    p.str(k.scheme)
                ))
            }
        },
    };
    let scheme = name.solid_scheme(&settings).map_err(|e| format!("scene `{scene}`: {e}"))?;
    Ok(SolidSetup { material, scheme, kernel, dx, h })
}

/// A solid scene's set-up for a rectangular block of particles (a plate, a beam, a flag):
/// the solid's [`SolidSetup`], the block's columns and rows, and the layers of a clamp.
#[derive(Clone, Debug)]
pub struct BlockSetup {
    /// The solid's set-up.
    pub solid: SolidSetup,
    /// Columns.
    pub nx: usize,
    /// Rows.
    pub ny: usize,
    /// Kernel support layers at the spacing: how deep a clamp must be.
    pub layers: usize,
}

impl SolidSetup {
    /// The block of `length` x `height` (m) at this spacing (`round(length / dx)` columns and
    /// `round(height / dx)` rows), named `what` in errors: refused when it has fewer than
    /// `min` (columns, rows) particles or more than [`check_count`] allows. The counts are
    /// taken in floating point first: a spacing of 1e-300 m must not overflow them.
    pub fn block(
        self,
        scene: &str,
        what: &str,
        (length, height): (f64, f64),
        min: (f64, f64),
    ) -> Result<BlockSetup, String> {
        let (nxf, nyf) = ((length / self.dx).round(), (height / self.dx).round());
        if nxf < min.0 || nyf < min.1 {
            return Err(format!("scene `{scene}`: {what} has fewer than {} x {} particles", min.0, min.1));
        }
        check_count(scene, what, nxf * nyf)?;
        let layers = self.support_layers();
        Ok(BlockSetup { solid: self, nx: nxf as usize, ny: nyf as usize, layers })
    }
}

/// A particle count in floating point first, refused beyond 5e6 particles (a spacing of
/// 1e-300 m must not overflow a count).
pub fn check_count(scene: &str, what: &str, count: f64) -> Result<(), String> {
    if count.is_nan() || count > 5e6 {
        return Err(format!("scene `{scene}`: {what} makes {count:.3e} particles: more than 5e6"));
    }
    Ok(())
}

/// Troughs and peaks of a signal followed step by step, with a hysteresis `delta`: a trough
/// is confirmed once the signal has risen `delta` above its running minimum, a peak once it
/// has fallen `delta` below its running maximum, so that noise smaller than `delta` makes no
/// extremum. Seeks a trough first.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Extrema {
    /// The hysteresis (m).
    pub delta: f64,
    /// Seeking a peak (after a trough) rather than a trough.
    pub rising: bool,
    /// The running extremum (t, y) since the last confirmed one.
    pub run: Option<(f64, f64)>,
    /// Confirmed troughs, (t, y).
    pub troughs: Vec<(f64, f64)>,
    /// Confirmed peaks, (t, y).
    pub peaks: Vec<(f64, f64)>,
}

impl Extrema {
    /// A detector that seeks a trough first (a flag released from rest falls).
    pub fn new(delta: f64) -> Self {
        Self { delta, ..Self::default() }
    }

    /// Takes the value `y` at time `t`.
    pub fn push(&mut self, t: f64, y: f64) {
        let (tr, yr) = *self.run.get_or_insert((t, y));
        if self.rising {
            if y > yr {
                self.run = Some((t, y));
            } else if y < yr - self.delta {
                self.peaks.push((tr, yr));
                self.rising = false;
                self.run = Some((t, y));
            }
        } else if y < yr {
            self.run = Some((t, y));
        } else if y > yr + self.delta {
            self.troughs.push((tr, yr));
            self.rising = true;
            self.run = Some((t, y));
        }
    }

    /// The last complete period: (mean, amplitude, frequency) from the last two troughs and
    /// the peak between them (module docs), if there are two troughs.
    pub fn last_period(&self) -> Option<(f64, f64, f64)> {
        let k = self.troughs.len();
        if k < 2 {
            return None;
        }
        let ((t1, y1), (t2, y2)) = (self.troughs[k - 2], self.troughs[k - 1]);
        let peak = self
            .peaks
            .iter()
            .filter(|(t, _)| *t > t1 && *t < t2)
            .map(|p| p.1)
            .fold(f64::NEG_INFINITY, f64::max);
        let low = y1.min(y2);
        Some((0.5 * (peak + low), 0.5 * (peak - low), 1.0 / (t2 - t1)))
    }
}

/// A point of a solid followed over a run: the mean position of some of its particles,
/// and its displacement from where it started.
#[derive(Clone, Debug)]
pub struct Probe {
    indices: Vec<usize>,
    start: Vector<2>,
}

impl Probe {
    /// The mean of the free particles of `solid` at which `pick` holds (`what` names them in
    /// the error when there are none).
    pub fn new(
        solid: &ElasticSolid<2>,
        what: &str,
        pick: impl Fn(&Vector<2>) -> bool,
    ) -> Result<Self, String> {
        let indices: Vec<usize> =
            (0..solid.len()).filter(|&i| !solid.fixed[i] && pick(&solid.x[i])).collect();
        if indices.is_empty() {
            return Err(format!("solid `{}`: no particle at {what}", solid.name));
        }
        let mut probe = Self { indices, start: Vector::zeros() };
        probe.start = probe.position(solid);
        Ok(probe)
    }

    /// How many particles it follows.
    pub fn count(&self) -> usize {
        self.indices.len()
    }

    /// The mean position of the particles now.
    pub fn position(&self, solid: &ElasticSolid<2>) -> Vector<2> {
        self.indices.iter().map(|&i| solid.x[i]).sum::<Vector<2>>() / self.indices.len() as f64
    }

    /// The displacement from the start.
    pub fn displacement(&self, solid: &ElasticSolid<2>) -> Vector<2> {
        self.position(solid) - self.start
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The extremum detector on a noisy cosine `y = -A (1 - cos 2 pi f t) + noise`: the
    /// last period gives mean -A, amplitude A and frequency f to within the noise (1e-3 A,
    /// far below the hysteresis of 0.1 A, which the noise must not trigger).
    #[test]
    fn the_extremum_detector_reads_a_noisy_oscillation() {
        let (a, f) = (0.065, 1.1);
        let mut e = Extrema::new(0.1 * a);
        for k in 0..40_000 {
            let t = k as f64 * 1e-4;
            let noise = 1e-3 * a * (k as f64 * 1.7).sin();
            e.push(t, -a * (1.0 - (2.0 * std::f64::consts::PI * f * t).cos()) + noise);
        }
        let (mean, amp, freq) = e.last_period().unwrap();
        assert!((mean + a).abs() < 2e-3 * a, "{mean}");
        assert!((amp - a).abs() < 2e-3 * a, "{amp}");
        assert!((freq - f).abs() < 1e-3 * f, "{freq}");
        assert_eq!(e.troughs.len(), 4, "{:?}", e.troughs);
    }
}
