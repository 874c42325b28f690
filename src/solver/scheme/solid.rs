//! The schemes of an elastic solid: which velocity its velocity gradient is taken of,
//! whether the transport-velocity correction terms are evaluated, how its particles are
//! homogenised, and its artificial viscosity and stress. `ctvf`, `gtvf_pst`, `gtvf` and
//! `gray` are values of [`SolidScheme`] built from one [`SolidSettings`]
//! ([`SolidSchemeName::solid_scheme`]), not separate code paths: they differ in switches.

use super::{paper, IpstTest, Pst, Shifting};
use serde::{Deserialize, Serialize};
use std::fmt;

/// The scheme names of a solid body.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SolidSchemeName {
    /// CTVF (Adepu & Ramachandran): the velocity gradient of the momentum velocity u
    /// (eq. 31) and the transport-velocity correction terms of eqs. (25) and (32).
    Ctvf,
    /// GTVF's solid equations under the shifting `pst` names: the velocity gradient of the
    /// transport velocity u~, no correction terms, particles shifted by Sun's shifting or
    /// IPST (CTVF fig. 18b's "GTVF with SPST").
    GtvfPst,
    /// GTVF (Zhang, Hu & Adams 2017) as its authors run it: [`GtvfPst`](Self::GtvfPst)'s equations
    /// homogenised by GTVF's own background pressure ([`GtvfBackground`]) instead of a
    /// shifting technique (CTVF fig. 18a, sec. 4.5's GTVF curve).
    Gtvf,
    /// Gray, Monaghan & Swift (2001): no transport velocity (no shifting), Monaghan's
    /// artificial stress against the tensile instability, as PySPH's
    /// `ElasticSolidsScheme` runs it.
    Gray,
}

named_choices!(SolidSchemeName {
    Ctvf => "ctvf",
    GtvfPst => "gtvf_pst",
    Gtvf => "gtvf",
    Gray => "gray",
});

impl SolidSchemeName {
    /// The parameters this scheme fixes itself (it refuses any other value), whose value a
    /// legend would misread as a choice: GTVF homogenises by its own background pressure
    /// and has no correction terms, so its `pst` = none is not "no shifting". Gray's are kept:
    /// its particles are indeed not shifted and uncorrected.
    pub fn fixed_keys(self) -> &'static [&'static str] {
        match self {
            SolidSchemeName::Gtvf => &["pst", "corrections"],
            _ => &[],
        }
    }
}

/// Monaghan's artificial stress (Gray et al. 2001, eqs. 4.7-4.10): `eps`, the exponent `n`
/// of `f_ab = W_ab / W(dx)`, and W(dx).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ArtificialStress {
    /// epsilon of R = -eps sigma / rho^2 in tension (0.3 in Gray et al. 2001 and PySPH).
    pub eps: f64,
    /// The exponent n of f_ab (4).
    pub n: i32,
    /// Kernel value at the initial spacing, W(dx).
    pub w_dx: f64,
}

/// The kernel gradient of a solid's sums: the paper's, or corrected (Bonet & Lok 1999).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SolidGradient {
    /// `grad W` as it is (CTVF eqs. 25, 30-32).
    Paper,
    /// `L_a grad W` with `L_a = (sum_b V_b grad W (x) x_ba)^-1`
    /// ([`correction_matrix`](crate::solver::equations::solid::correction_matrix)) in the
    /// particle's density and stress rates, and each particle's own in the momentum equation
    /// ([`momentum_corrected`](crate::solver::equations::solid::momentum_corrected)): the
    /// gradient of a linear field is then exact at a free surface too, where the paper's
    /// sees half a support. Beyond the paper.
    Corrected,
}

named_choices!(SolidGradient {
    Paper => "paper",
    Corrected => "corrected",
});

/// How a solid's shift is kept from the free surface next to it (the surface particles
/// themselves are never shifted).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SurfaceShift {
    /// Eqs. (44)-(45) as printed: the normal component removed.
    #[default]
    Normal,
    /// As the authors' code does for solids: the normal component removed only when it
    /// points out of the body
    /// ([`adjust_shift_outward`](crate::solver::equations::free_surface::adjust_shift_outward)).
    Outward,
}

named_choices!(SurfaceShift {
    Normal => "normal",
    Outward => "outward",
});

/// GTVF's homogenisation (Zhang, Hu & Adams 2017; CTVF eq. 20 as the authors' code
/// `ComputeAuHatGTVF` evaluates it): `(du/dt)_c = -p0_a / rho_a^2 sum_b m_b grad W(x_ab, h/2)`
/// with the particle's background pressure `p0_a = min(10 |p_a|, p_ref)`
/// ([`gtvf_background_pressure`](crate::solver::equations::shifting::gtvf_background_pressure)).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct GtvfBackground {
    /// The cap `p_ref` of the background pressure (Pa): the bulk modulus in the authors' code.
    pub p_ref: f64,
}

/// Which velocity the velocity gradient of eq. (31) is taken of.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum GradientVelocity {
    /// The momentum velocity u (CTVF eq. 31).
    Momentum,
    /// The transport velocity u~ (GTVF).
    Transport,
}

/// Sun et al. (2019) shifting of a solid, eq. (36):
/// `-(Ma 2h c0 / dt) sum V_b [1 + R (W/W(dx))^n] grad W`.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SolidShifting {
    /// Mach number times speed of sound: the reference speed Ma c0.
    pub ma_c0: f64,
    /// Kernel value at the initial spacing, W(dx).
    pub w_dx: f64,
    /// R of eq. (36).
    pub r: f64,
    /// n of eq. (36).
    pub n: i32,
}

/// IPST's tolerance on a solid (eq. 39): 0.2, the authors' code's value outside internal
/// flows, rather than the fluids' 0.02. An elastic solid's density varies by its
/// volumetric strain (a bent plate is some per cent denser on its compressed side), which the
/// fluids' 0.02 reads as disorder: IPST then moves particles across the plate at every step,
/// as a plastic flow would, and stops it oscillating.
pub const SOLID_IPST_TOL: f64 = 0.2;

/// What a solid body's equations are (its material constants live on the body).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct SolidScheme {
    /// The name this composition was built from.
    pub name: SolidSchemeName,
    /// The velocity of the velocity gradient (eq. 31).
    pub gradient: GradientVelocity,
    /// The transport-velocity correction terms of eq. (25) and eq. (32).
    pub corrections: bool,
    /// Sun's shifting (the particles then move with u~, eq. 33).
    pub shifting: Option<SolidShifting>,
    /// IPST (eqs. 37-41, [`Shifting::Ipst`]), the other way to make u~; `chi_ref` is set
    /// from the initial configuration when the simulation starts.
    #[serde(default)]
    pub ipst: Option<Shifting>,
    /// GTVF's background-pressure homogenisation, the third way to make u~ (`gtvf`).
    #[serde(default)]
    pub background_pressure: Option<GtvfBackground>,
    /// Monaghan's artificial viscosity alpha (eq. 28), if any.
    pub artificial_viscosity: Option<f64>,
    /// Monaghan's artificial stress (`gray`), if any.
    #[serde(default)]
    pub artificial_stress: Option<ArtificialStress>,
    /// Detect the free surface (sec. 3.4) and keep the shifting tangential near it (eq. 44).
    pub free_surface: bool,
    /// How the shift near the free surface is kept from it.
    #[serde(default)]
    pub surface_shift: SurfaceShift,
    /// The kernel-gradient correction ([`SolidGradient::Corrected`]); false: the paper's.
    #[serde(default)]
    pub kernel_correction: bool,
    /// Body force per unit mass.
    pub gravity: [f64; 3],
}

impl SolidScheme {
    /// Whether the particles move with a transport velocity u~ (Sun's shifting, IPST or
    /// GTVF's background pressure).
    pub fn transports(&self) -> bool {
        self.shifting.is_some() || self.ipst.is_some() || self.background_pressure.is_some()
    }

    /// Gravity as a `D`-vector.
    pub fn gravity_vector<const D: usize>(&self) -> crate::solver::math::Vector<D> {
        crate::solver::math::Vector::<D>::from_fn(|k, _| self.gravity[k])
    }
}

/// What a scene gives a solid scheme name to build a [`SolidScheme`] from.
#[derive(Clone, Copy, Debug)]
pub struct SolidSettings {
    /// Particle shifting: Sun 2019, IPST or none.
    pub pst: Pst,
    /// The correction terms (read by `ctvf`; the others have none).
    pub corrections: bool,
    /// Artificial viscosity alpha of eq. (28); 0: none.
    pub alpha: f64,
    /// The reference speed U = Ma c0 of Sun's shifting (eq. 36).
    pub u_ref: f64,
    /// W(dx) for Sun's shifting.
    pub w_dx: f64,
    /// Body force per unit mass.
    pub gravity: [f64; 3],
    /// The kernel gradient: the paper's or corrected.
    pub gradient: SolidGradient,
    /// The cap `p_ref` of GTVF's background pressure (Pa; read by `gtvf` only).
    pub p_ref: f64,
    /// How the shift near the free surface is kept from it (Sun's shifting and IPST).
    pub surface_shift: SurfaceShift,
}

#[cfg(test)]
impl SolidSettings {
    /// The settings the solid tests share: CTVF's corrections, alpha = 1, unit reference
    /// speed and GTVF cap, no gravity, the paper's kernel gradient; each test changes what
    /// it studies by struct update.
    pub fn for_tests(pst: Pst, w_dx: f64) -> Self {
        SolidSettings {
            pst,
            corrections: true,
            alpha: 1.0,
            u_ref: 1.0,
            w_dx,
            gravity: [0.0; 3],
            gradient: SolidGradient::Paper,
            p_ref: 1.0,
            surface_shift: SurfaceShift::Normal,
        }
    }
}

impl SolidSchemeName {
    /// The composition this name stands for. `gray` has no transport velocity and `gtvf`
    /// homogenises with its own background pressure, so both take `pst` = none only. IPST
    /// runs at the paper's tolerance and cap ([`paper`]) with the reference speed `u_ref` as
    /// its U_max.
    pub fn solid_scheme(self, s: &SolidSettings) -> Result<SolidScheme, String> {
        let own = match self {
            SolidSchemeName::Gray => Some("has no transport velocity to shift with"),
            SolidSchemeName::Gtvf => Some("homogenises with its own background pressure (Zhang et al. 2017)"),
            _ => None,
        };
        if let (Some(why), true) = (own, s.pst != Pst::None) {
            return Err(format!(
                "`scheme` = {} {why}: `pst` = {} is refused (give `pst` = none)",
                Self::NAMES[self as usize],
                Pst::NAMES[s.pst as usize]
            ));
        }
        if self == SolidSchemeName::Gtvf && !(s.p_ref > 0.0 && s.p_ref.is_finite()) {
            return Err(format!(
                "GTVF's background pressure cap p_ref = {:?} Pa must be positive and finite",
                s.p_ref
            ));
        }
        let shifting =
            (s.pst == Pst::Sun).then_some(SolidShifting { ma_c0: s.u_ref, w_dx: s.w_dx, r: 0.2, n: 4 });
        let ipst = (s.pst == Pst::Ipst).then_some(Shifting::Ipst {
            u_max: s.u_ref,
            tol: SOLID_IPST_TOL,
            max_iter: paper::IPST_MAX_ITER,
            interval: paper::IPST_INTERVAL,
            chi_ref: f64::NAN, // measured on the initial configuration
            test: IpstTest::default(),
        });
        let background_pressure =
            (self == SolidSchemeName::Gtvf).then_some(GtvfBackground { p_ref: s.p_ref });
        // Sun's shifting and IPST keep the free surface (sec. 3.4); GTVF's background
        // pressure vanishes there by itself.
        let shifted = shifting.is_some() || ipst.is_some();
        let transports = shifted || background_pressure.is_some();
        let (gradient, corrections) = match self {
            SolidSchemeName::Ctvf => (GradientVelocity::Momentum, s.corrections),
            SolidSchemeName::GtvfPst | SolidSchemeName::Gtvf => (GradientVelocity::Transport, false),
            SolidSchemeName::Gray => (GradientVelocity::Momentum, false),
        };
        let artificial_stress =
            (self == SolidSchemeName::Gray).then_some(ArtificialStress { eps: 0.3, n: 4, w_dx: s.w_dx });
        Ok(SolidScheme {
            name: self,
            gradient,
            corrections: corrections && transports,
            shifting,
            ipst,
            background_pressure,
            artificial_viscosity: (s.alpha > 0.0).then_some(s.alpha),
            artificial_stress,
            free_surface: shifted,
            surface_shift: s.surface_shift,
            gravity: s.gravity,
            kernel_correction: s.gradient == SolidGradient::Corrected,
        })
    }
}

impl fmt::Display for SolidScheme {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = SolidSchemeName::NAMES[self.name as usize];
        writeln!(f, "solid scheme {name}:")?;
        writeln!(
            f,
            "  density: continuity, eq. (25){}",
            if self.corrections { " with its correction" } else { "" }
        )?;
        writeln!(f, "  pressure: state equation p = K (rho/rho0 - 1), eq. (8)")?;
        let v = match self.gradient {
            GradientVelocity::Momentum => "u (eq. 31)",
            GradientVelocity::Transport => "u~ (GTVF)",
        };
        writeln!(
            f,
            "  deviatoric stress: Jaumann rate, eqs. (4), (32); velocity gradient of {v}{}",
            if self.corrections { "; transport terms of eq. (32)" } else { "" }
        )?;
        if self.kernel_correction {
            writeln!(f, "  kernel gradient: corrected, L grad W (Bonet & Lok 1999; beyond the paper)")?;
        }
        match self.artificial_viscosity {
            Some(a) => writeln!(f, "  momentum: eq. (30), artificial viscosity alpha = {a} (eq. 28)")?,
            None => writeln!(f, "  momentum: eq. (30)")?,
        }
        if let Some(a) = self.artificial_stress {
            writeln!(f, "  artificial stress: Monaghan (Gray et al. 2001), eps = {}, n = {}", a.eps, a.n)?;
        }
        match self.shifting {
            Some(s) => write!(
                f,
                "  shifting: Sun 2019, eq. (36), Ma c0 = {:.4e}, R = {}, n = {}{}",
                s.ma_c0,
                s.r,
                s.n,
                match (self.free_surface, self.surface_shift) {
                    (false, _) => "",
                    (true, SurfaceShift::Normal) => "; tangential near the free surface, eq. (44)",
                    (true, SurfaceShift::Outward) => "; near the free surface not outwards (eq. 44 as the authors' code applies it)",
                }
            ),
            None => match (self.ipst, self.background_pressure) {
                (Some(Shifting::Ipst { tol, max_iter, interval, .. }), _) => write!(
                    f,
                    "  shifting: IPST, eqs. (37)-(41): tol = {tol}, max {max_iter} iterations, every {interval} step(s); away from the free surface (sec. 3.4){}",
                    if self.surface_shift == SurfaceShift::Outward { ", near it not outwards" } else { "" }
                ),
                (_, Some(b)) => write!(
                    f,
                    "  shifting: GTVF's background pressure, eq. (20) with grad W at h/2, p0 = min(10 |p|, {:.4e} Pa)",
                    b.p_ref
                ),
                _ => write!(f, "  shifting: none (particles move with u)"),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn settings(pst: Pst) -> SolidSettings {
        SolidSettings { p_ref: 2.0, ..SolidSettings::for_tests(pst, 1.0) }
    }

    /// `ctvf` and `gtvf_pst` differ in the gradient's velocity and the corrections only; `gtvf`
    /// is `gtvf_pst` homogenised by its background pressure instead of a shifting technique.
    #[test]
    fn the_solid_schemes_differ_in_switches() {
        let c = SolidSchemeName::Ctvf.solid_scheme(&settings(Pst::Sun)).unwrap();
        let t = SolidSchemeName::GtvfPst.solid_scheme(&settings(Pst::Sun)).unwrap();
        assert_eq!((c.gradient, c.corrections), (GradientVelocity::Momentum, true));
        assert_eq!((t.gradient, t.corrections), (GradientVelocity::Transport, false));
        let same = SolidScheme { name: c.name, gradient: c.gradient, corrections: c.corrections, ..t };
        assert_eq!(same, c);
        let g = SolidSchemeName::Gtvf.solid_scheme(&settings(Pst::None)).unwrap();
        let as_tvf = SolidScheme {
            name: t.name,
            shifting: t.shifting,
            free_surface: t.free_surface,
            background_pressure: None,
            ..g
        };
        assert_eq!(as_tvf, t);
        assert_eq!(g.background_pressure, Some(GtvfBackground { p_ref: 2.0 }));
        assert!(g.transports() && !g.free_surface && g.shifting.is_none() && g.ipst.is_none());
        let e = SolidSchemeName::Gtvf.solid_scheme(&settings(Pst::Sun)).unwrap_err();
        assert!(e.contains("`scheme` = gtvf") && e.contains("`pst` = sun"), "{e}");
        let e = SolidSchemeName::Gtvf
            .solid_scheme(&SolidSettings { p_ref: 0.0, ..settings(Pst::None) })
            .unwrap_err();
        assert!(e.contains("p_ref = 0.0"), "{e}");
        let ipst = SolidSchemeName::Ctvf.solid_scheme(&settings(Pst::Ipst)).unwrap();
        assert!(ipst.shifting.is_none() && ipst.ipst.is_some() && ipst.transports() && ipst.corrections);
        let gray = SolidSchemeName::Gray.solid_scheme(&settings(Pst::None)).unwrap();
        assert!(gray.shifting.is_none() && !gray.corrections && gray.artificial_stress.is_some());
        assert!(SolidSchemeName::Gray.solid_scheme(&settings(Pst::Sun)).unwrap_err().contains("gray"));
        assert!(
            c.artificial_stress.is_none() && t.artificial_stress.is_none() && g.artificial_stress.is_none()
        );
        let still = SolidSchemeName::Ctvf.solid_scheme(&settings(Pst::None)).unwrap();
        assert!(still.shifting.is_none() && !still.corrections, "no transport velocity: nothing to correct");
    }
}
