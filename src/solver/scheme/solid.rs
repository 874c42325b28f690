//! The schemes of an elastic solid: which velocity its velocity gradient is taken of,
//! whether the transport-velocity correction terms are evaluated, how its particles are
//! homogenised, and its artificial viscosity and stress. `ctvf`, `gtvf` and `gray` are
//! values of [`SolidScheme`] built from one [`SolidSettings`]
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
    /// GTVF (Zhang, Hu & Adams 2017): the velocity gradient of the transport velocity u~,
    /// no correction terms (CTVF sec. 4.4 and 5 compare the two).
    Gtvf,
    /// Gray, Monaghan & Swift (2001): no transport velocity (no shifting), Monaghan's
    /// artificial stress against the tensile instability, as PySPH's
    /// `ElasticSolidsScheme` runs it.
    Gray,
}

named_choices!(SolidSchemeName {
    Ctvf => "ctvf",
    Gtvf => "gtvf",
    Gray => "gray",
});

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
    /// Monaghan's artificial viscosity alpha (eq. 28), if any.
    pub artificial_viscosity: Option<f64>,
    /// Monaghan's artificial stress (`gray`), if any.
    #[serde(default)]
    pub artificial_stress: Option<ArtificialStress>,
    /// Detect the free surface (sec. 3.4) and keep the shifting tangential near it (eq. 44).
    pub free_surface: bool,
    /// Body force per unit mass.
    pub gravity: [f64; 3],
}

impl SolidScheme {
    /// Whether the particles move with a transport velocity u~ (Sun's shifting or IPST).
    pub fn transports(&self) -> bool {
        self.shifting.is_some() || self.ipst.is_some()
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
    /// The correction terms (read by `ctvf`; `gtvf` has none).
    pub corrections: bool,
    /// Artificial viscosity alpha of eq. (28); 0: none.
    pub alpha: f64,
    /// The reference speed U = Ma c0 of Sun's shifting (eq. 36).
    pub u_ref: f64,
    /// W(dx) for Sun's shifting.
    pub w_dx: f64,
    /// Body force per unit mass.
    pub gravity: [f64; 3],
}

impl SolidSchemeName {
    /// The composition this name stands for. `gray` has no transport velocity, so it takes
    /// `pst` = none only. IPST runs at the paper's tolerance and cap ([`paper`]) with the
    /// reference speed `u_ref` as its U_max.
    pub fn solid_scheme(self, s: &SolidSettings) -> Result<SolidScheme, String> {
        if self == SolidSchemeName::Gray && s.pst != Pst::None {
            return Err(format!(
                "`scheme` = gray has no transport velocity to shift with: `pst` = {} is refused (give `pst` = none)",
                Pst::NAMES[s.pst as usize]
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
        let transports = shifting.is_some() || ipst.is_some();
        let (gradient, corrections) = match self {
            SolidSchemeName::Ctvf => (GradientVelocity::Momentum, s.corrections),
            SolidSchemeName::Gtvf => (GradientVelocity::Transport, false),
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
            artificial_viscosity: (s.alpha > 0.0).then_some(s.alpha),
            artificial_stress,
            free_surface: transports,
            gravity: s.gravity,
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
                if self.free_surface { "; tangential near the free surface, eq. (44)" } else { "" }
            ),
            None => match self.ipst {
                Some(Shifting::Ipst { tol, max_iter, interval, .. }) => write!(
                    f,
                    "  shifting: IPST, eqs. (37)-(41): tol = {tol}, max {max_iter} iterations, every {interval} step(s); away from the free surface (sec. 3.4)"
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
        SolidSettings { pst, corrections: true, alpha: 1.0, u_ref: 1.0, w_dx: 1.0, gravity: [0.0; 3] }
    }

    /// `ctvf` and `gtvf` differ in the gradient's velocity and the corrections only.
    #[test]
    fn ctvf_and_gtvf_differ_in_two_switches() {
        let c = SolidSchemeName::Ctvf.solid_scheme(&settings(Pst::Sun)).unwrap();
        let g = SolidSchemeName::Gtvf.solid_scheme(&settings(Pst::Sun)).unwrap();
        assert_eq!((c.gradient, c.corrections), (GradientVelocity::Momentum, true));
        assert_eq!((g.gradient, g.corrections), (GradientVelocity::Transport, false));
        let same = SolidScheme { name: c.name, gradient: c.gradient, corrections: c.corrections, ..g };
        assert_eq!(same, c);
        let ipst = SolidSchemeName::Ctvf.solid_scheme(&settings(Pst::Ipst)).unwrap();
        assert!(ipst.shifting.is_none() && ipst.ipst.is_some() && ipst.transports() && ipst.corrections);
        let gray = SolidSchemeName::Gray.solid_scheme(&settings(Pst::None)).unwrap();
        assert!(gray.shifting.is_none() && !gray.corrections && gray.artificial_stress.is_some());
        assert!(SolidSchemeName::Gray.solid_scheme(&settings(Pst::Sun)).unwrap_err().contains("gray"));
        assert!(c.artificial_stress.is_none() && g.artificial_stress.is_none());
        let still = SolidSchemeName::Ctvf.solid_scheme(&settings(Pst::None)).unwrap();
        assert!(still.shifting.is_none() && !still.corrections, "no transport velocity: nothing to correct");
    }
}
