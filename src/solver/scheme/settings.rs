//! From what a scene gives to a scheme: the constants and switches of a fluid
//! ([`FluidSettings`]), the composition a scheme name stands for
//! ([`SchemeName::fluid_scheme`]), and the check that every option a user gave is read by
//! the scheme asked for ([`SchemeOptions`]).

use super::{
    paper, Corrections, DensityModel, FluidScheme, FreeSurface, IpstTest, PressureGradient, PressureModel,
    PressureReference, Pst, SchemeName, Shifting, SurfaceCone, SurfacePressure, Transport,
};

/// What a scene gives a scheme name to build a [`FluidScheme`] from.
#[derive(Clone, Copy, Debug)]
pub struct FluidSettings {
    /// Reference density rho_0.
    pub rho0: f64,
    /// Speed of sound c_0.
    pub c0: f64,
    /// Reference (maximum) velocity U.
    pub u_ref: f64,
    /// Smoothing length h.
    pub h: f64,
    /// W(dx) for the Sun 2019 shifting.
    pub w_dx: f64,
    /// Kinematic viscosity, if any.
    pub nu: Option<f64>,
    /// Artificial viscosity alpha, if any.
    pub alpha: Option<f64>,
    /// alpha_edac of eq. (24).
    pub edac_alpha: f64,
    /// Density model for CTVF (summation for internal flows, continuity with a free surface).
    pub density: DensityModel,
    /// Shifting technique for CTVF.
    pub pst: Pst,
    /// CTVF corrections.
    pub corrections: Corrections,
    /// IPST tolerance and iteration cap.
    pub ipst_tol: f64,
    /// IPST iteration cap.
    pub ipst_max_iter: usize,
    /// IPST on every this many steps.
    pub ipst_interval: usize,
    /// Gravity.
    pub gravity: [f64; 3],
    /// The reference pressure of the pressure gradient (`Auto` also depends on the walls,
    /// which the simulation's builder resolves, [`FluidScheme::resolve_reference`]).
    pub pressure_reference: PressureReference,
    /// A free surface to detect (sec. 3.4-3.5), with what its particles' pressure does.
    pub free_surface: Option<SurfacePressure>,
    /// The neighbours of the free surface's 60-degree test.
    pub surface_cone: SurfaceCone,
    /// Which deviation fails IPST's test.
    pub ipst_test: IpstTest,
}

impl FluidSettings {
    /// A viscous internal flow (no free surface, no gravity) with the [`paper`]'s defaults:
    /// summation density, Sun's shifting, every correction, and the scheme's own pressure
    /// reference. `w_dx` is W(dx) for Sun's shifting, `nu` the
    /// kinematic viscosity.
    pub fn internal_flow(rho0: f64, c0: f64, u_ref: f64, h: f64, w_dx: f64, nu: f64) -> Self {
        Self {
            rho0,
            c0,
            u_ref,
            h,
            w_dx,
            nu: Some(nu),
            alpha: None,
            edac_alpha: paper::EDAC_ALPHA,
            density: DensityModel::Summation,
            pst: Pst::Sun,
            corrections: Corrections::ALL,
            ipst_tol: paper::IPST_TOL,
            ipst_max_iter: paper::IPST_MAX_ITER,
            ipst_interval: paper::IPST_INTERVAL,
            gravity: [0.0; 3],
            pressure_reference: PressureReference::Auto,
            free_surface: None,
            surface_cone: SurfaceCone::Support,
            ipst_test: IpstTest::TwoSided,
        }
    }
}

impl SchemeName {
    /// Whether the scheme subtracts the neighbours' mean pressure (BQL) under
    /// `pressure_reference = auto`, for a fluid `bounded` by walls or a free surface. `edac`
    /// does, as PySPH's EDACScheme; `tvf` does not. `ctvf` does only without boundaries (a
    /// periodic box: the Taylor-Green vortex needs it), and follows eq. (27) as printed
    /// otherwise (the lid-driven cavity needs that; see [`PressureReference`]).
    pub fn bql_by_default(self, bounded: bool) -> bool {
        match self {
            SchemeName::Edac => true,
            SchemeName::Tvf => false,
            SchemeName::Ctvf => !bounded,
        }
    }

    /// The composition this scheme name stands for, for a fluid without boundaries (the
    /// simulation resolves the pressure reference for the boundaries it finds,
    /// [`FluidScheme::resolve_reference`]).
    pub fn fluid_scheme(self, s: &FluidSettings) -> FluidScheme {
        let edac = PressureModel::Edac {
            cs: s.c0,
            nu: crate::solver::equations::edac::nu_edac(s.edac_alpha, s.h, s.c0),
        };
        // Adami et al. (2013): p_b = rho0 c0^2, applied over half a step (eq. 55), as
        // PySPH's TVF integrator does. PySPH's EDAC scheme integrates with a midpoint
        // predictor-corrector whose final stage sets u~ = u + dt a_c, i.e. twice the
        // homogenisation of eq. (55): in our kick-drift-kick that is p_b = 2 rho0 c0^2.
        let background = |factor: f64| Transport {
            shifting: Shifting::BackgroundPressure { pb: factor * s.rho0 * s.c0 * s.c0 },
            corrections: Corrections::NONE,
        };
        // What every scheme shares; each differs from it in the density, pressure,
        // pressure gradient, transport velocity and free surface below.
        let base = FluidScheme {
            name: self,
            c0: s.c0,
            u_ref: s.u_ref,
            density: DensityModel::Summation,
            pressure: edac,
            pressure_gradient: PressureGradient::Adami { bql: false },
            pressure_reference: s.pressure_reference,
            viscosity: s.nu,
            artificial_viscosity: s.alpha.filter(|&a| a > 0.0).map(|a| (a, s.c0)),
            transport: None,
            gravity: s.gravity,
            free_surface: None,
        };
        let mut scheme = match self {
            SchemeName::Edac => FluidScheme { transport: Some(background(2.0)), ..base },
            SchemeName::Tvf => FluidScheme {
                pressure: PressureModel::StateEquation { c0: s.c0, rho0: s.rho0 },
                transport: Some(background(1.0)),
                ..base
            },
            SchemeName::Ctvf => {
                let shifting = match s.pst {
                    Pst::Sun => Some(Shifting::Sun2019 { ma_c0: s.u_ref, w_dx: s.w_dx, r: 0.2, n: 4 }),
                    Pst::Ipst => Some(Shifting::Ipst {
                        u_max: s.u_ref,
                        tol: s.ipst_tol,
                        max_iter: s.ipst_max_iter,
                        interval: s.ipst_interval,
                        chi_ref: f64::NAN, // measured on the initial configuration
                        test: s.ipst_test,
                    }),
                    Pst::None => None,
                };
                FluidScheme {
                    density: s.density,
                    pressure_gradient: PressureGradient::Symmetric { bql: false },
                    transport: shifting.map(|shifting| Transport { shifting, corrections: s.corrections }),
                    free_surface: s.free_surface.map(|pressure| FreeSurface {
                        rho0: s.rho0,
                        pressure,
                        cone: s.surface_cone,
                    }),
                    ..base
                }
            }
        };
        scheme.resolve_reference(false);
        scheme
    }
}

/// A scheme option given for a scheme that does not read it: `key` names the option (as
/// the scenes name their parameters), `why` says which scheme reads it.
#[derive(Clone, Debug, PartialEq)]
pub struct OptionError {
    /// The option's name.
    pub key: &'static str,
    /// Why it has no effect here.
    pub why: String,
}

/// The scheme options a user gave, each `None` unless given (a value at its default counts
/// as not given). Each is read by one scheme only; [`check`](Self::check) refuses one given
/// for a scheme that would ignore it, so that a run asked for as "edac with IPST" is not
/// silently plain `edac`. The values that switch an option off pass for every scheme.
#[derive(Clone, Copy, Debug, Default)]
pub struct SchemeOptions {
    /// Particle shifting (`ctvf`).
    pub pst: Option<Pst>,
    /// Every CTVF correction together, on or off (`ctvf`).
    pub corrections: Option<bool>,
    /// The correction of eq. (25) alone (`ctvf`).
    pub corr_continuity: Option<bool>,
    /// The corrections of eq. (26) alone (`ctvf`).
    pub corr_pressure: Option<bool>,
    /// The momentum correction alone (`ctvf`).
    pub corr_momentum: Option<bool>,
    /// IPST's tolerance (`ctvf` with `pst = ipst`).
    pub ipst_tol: Option<f64>,
    /// IPST's iteration cap (`ctvf` with `pst = ipst`).
    pub ipst_max_iter: Option<usize>,
    /// IPST's interval (`ctvf` with `pst = ipst`).
    pub ipst_interval: Option<usize>,
    /// IPST's test (`ctvf` with `pst = ipst`).
    pub ipst_test: Option<IpstTest>,
    /// alpha of nu_edac, eq. (24) (the EDAC schemes: not `tvf`).
    pub edac_alpha: Option<f64>,
}

impl SchemeOptions {
    /// Refuses an option given for `scheme` that it does not read (the first found, in
    /// the order of the fields). `pst` is the shifting the scheme will use (given or its
    /// default), which IPST's options need.
    pub fn check(&self, scheme: SchemeName, pst: Pst) -> Result<(), OptionError> {
        let ctvf = scheme == SchemeName::Ctvf;
        let name = SchemeName::NAMES[scheme as usize];
        let on = [
            ("pst", self.pst.is_some_and(|p| p != Pst::None)),
            ("corrections", self.corrections == Some(true)),
            ("corr_continuity", self.corr_continuity == Some(true)),
            ("corr_pressure", self.corr_pressure == Some(true)),
            ("corr_momentum", self.corr_momentum == Some(true)),
        ];
        if let Some((key, _)) = on.iter().find(|(_, given)| !ctvf && *given) {
            return Err(OptionError {
                key,
                why: format!(
                    "has no effect with `scheme` = {name}: particle shifting and the correction terms are ctvf's (edac and tvf homogenise with a background pressure)"
                ),
            });
        }
        let ipst = [
            ("ipst_tol", self.ipst_tol.is_some()),
            ("ipst_max_iter", self.ipst_max_iter.is_some()),
            ("ipst_interval", self.ipst_interval.is_some()),
            ("ipst_test", self.ipst_test.is_some()),
        ];
        if let Some((key, _)) = ipst.iter().find(|(_, given)| *given && !(ctvf && pst == Pst::Ipst)) {
            let why = if ctvf {
                format!("`pst` = {}", Pst::NAMES[pst as usize])
            } else {
                format!("`scheme` = {name}")
            };
            return Err(OptionError {
                key,
                why: format!(
                    "has no effect with {why}: IPST's settings act with scheme = ctvf and pst = ipst"
                ),
            });
        }
        if scheme == SchemeName::Tvf && self.edac_alpha.is_some() {
            return Err(OptionError {
                key: "edac_alpha",
                why: "has no effect with `scheme` = tvf: its pressure comes from the state equation".into(),
            });
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each option is refused for the schemes that do not read it, and passes for the one
    /// that does, or where it switches something off.
    #[test]
    fn options_are_refused_where_their_scheme_does_not_read_them() {
        use SchemeName::{Ctvf, Edac, Tvf};
        let given = |f: fn(&mut SchemeOptions)| {
            let mut o = SchemeOptions::default();
            f(&mut o);
            o
        };
        let pst_ipst = given(|o| o.pst = Some(Pst::Ipst));
        assert_eq!(pst_ipst.check(Edac, Pst::Ipst).unwrap_err().key, "pst");
        assert!(pst_ipst.check(Ctvf, Pst::Ipst).is_ok());
        assert!(given(|o| o.pst = Some(Pst::None)).check(Tvf, Pst::None).is_ok(), "off passes");
        assert!(given(|o| o.corrections = Some(false)).check(Edac, Pst::Sun).is_ok(), "off passes");
        assert_eq!(
            given(|o| o.corr_momentum = Some(true)).check(Tvf, Pst::Sun).unwrap_err().key,
            "corr_momentum"
        );
        let tol = given(|o| o.ipst_tol = Some(0.1));
        assert_eq!(tol.check(Ctvf, Pst::Sun).unwrap_err().key, "ipst_tol");
        assert!(tol.check(Ctvf, Pst::Sun).unwrap_err().why.contains("`pst` = sun"));
        assert!(tol.check(Edac, Pst::Ipst).unwrap_err().why.contains("`scheme` = edac"));
        assert!(tol.check(Ctvf, Pst::Ipst).is_ok());
        let alpha = given(|o| o.edac_alpha = Some(1.0));
        assert_eq!(alpha.check(Tvf, Pst::Sun).unwrap_err().key, "edac_alpha");
        assert!(alpha.check(Edac, Pst::Sun).is_ok() && alpha.check(Ctvf, Pst::Sun).is_ok());
    }
}
