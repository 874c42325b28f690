//! A scheme's terms as bits: its plan. The pair loops of the passes are generic over a
//! plan known at compile time, so the loops of the named schemes carry no per-neighbour
//! checks of which terms are on (5 % of an `edac` step, measured with `sphrepro bench`);
//! any other composition runs the same code with the plan read at run time
//! ([`RUNTIME`]). Either way the terms are the same functions, summed in the same order:
//! results are bit for bit those of the run-time plan.

/// Pass B: the Adami et al. (2013) pressure gradient (else the symmetric one of eq. 27).
pub const ADAMI: u32 = 1 << 0;
/// Pass B: the neighbour-mean pressure as reference (BQL).
pub const BQL: u32 = 1 << 1;
/// Pass B: Morris viscosity.
pub const VISCOSITY: u32 = 1 << 2;
/// Pass B: Monaghan artificial viscosity (eqs. 28-29).
pub const ARTIFICIAL_VISCOSITY: u32 = 1 << 3;
/// Pass B: a transport velocity (artificial stress).
pub const TRANSPORT: u32 = 1 << 4;
/// Pass B: the CTVF momentum correction.
pub const MOMENTUM_CORR: u32 = 1 << 5;
/// Pass B: homogenisation by a background pressure.
pub const BACKGROUND_PRESSURE: u32 = 1 << 6;
/// Pass B: homogenisation by Sun et al. (2019), eq. (36).
pub const SUN2019: u32 = 1 << 7;
/// Pass A: the EDAC pressure rate (eq. 26).
pub const EDAC: u32 = 1 << 8;
/// Pass A: the CTVF pressure correction (eq. 23).
pub const PRESSURE_CORR: u32 = 1 << 9;
/// Pass A: the continuity equation (eq. 25).
pub const CONTINUITY: u32 = 1 << 10;
/// Pass A: the CTVF continuity correction.
pub const CONTINUITY_CORR: u32 = 1 << 11;
/// Not a term: the plan is read at run time, not compiled in.
pub const RUNTIME: u32 = 1 << 31;

/// The plans of pass B that the named schemes take on the paper's benchmarks (tested):
/// `edac` and `tvf`, then `ctvf` with Sun's shifting, IPST or none, with and without the
/// momentum correction, on periodic internal flows (viscous, BQL), within walls (viscous)
/// and on free surfaces (artificial viscosity).
pub const ACCELERATIONS: [u32; 17] = [
    ADAMI | BQL | VISCOSITY | TRANSPORT | BACKGROUND_PRESSURE,
    ADAMI | VISCOSITY | TRANSPORT | BACKGROUND_PRESSURE,
    BQL | VISCOSITY | TRANSPORT | MOMENTUM_CORR | SUN2019,
    BQL | VISCOSITY | TRANSPORT | SUN2019,
    BQL | VISCOSITY | TRANSPORT | MOMENTUM_CORR,
    BQL | VISCOSITY | TRANSPORT,
    BQL | VISCOSITY,
    VISCOSITY | TRANSPORT | MOMENTUM_CORR | SUN2019,
    VISCOSITY | TRANSPORT | SUN2019,
    VISCOSITY | TRANSPORT | MOMENTUM_CORR,
    VISCOSITY | TRANSPORT,
    VISCOSITY,
    ARTIFICIAL_VISCOSITY | TRANSPORT | MOMENTUM_CORR | SUN2019,
    ARTIFICIAL_VISCOSITY | TRANSPORT | SUN2019,
    ARTIFICIAL_VISCOSITY | TRANSPORT | MOMENTUM_CORR,
    ARTIFICIAL_VISCOSITY | TRANSPORT,
    ARTIFICIAL_VISCOSITY,
];

/// The plans of pass A, likewise: EDAC with and without the pressure correction (internal
/// flows), with the continuity equation with and without its corrections (free surfaces).
pub const RATES: [u32; 4] =
    [EDAC, EDAC | PRESSURE_CORR, EDAC | CONTINUITY, EDAC | PRESSURE_CORR | CONTINUITY | CONTINUITY_CORR];

/// `t` if `on`, else no bit.
pub fn bit(on: bool, t: u32) -> u32 {
    if on {
        t
    } else {
        0
    }
}

/// Whether term `t` is on in the compiled plan `P`, or, for `P` = [`RUNTIME`], in `plan`.
#[inline(always)]
pub fn has<const P: u32>(plan: u32, t: u32) -> bool {
    if P == RUNTIME {
        plan & t != 0
    } else {
        P & t != 0
    }
}

/// `with_plan!(LIST; plan, P => body; 0 1 ...)` evaluates `body` with the const `P` bound
/// to `plan` if `plan` is `LIST[k]` for one of the listed indices (which must cover `LIST`,
/// checked at compile time), else to [`RUNTIME`].
macro_rules! with_plan {
    ($list:expr; $plan:expr, $p:ident => $body:expr; $($k:literal)*) => {{
        const _: () = assert!($list.len() == [$($k),*].len(), "list every compiled plan");
        match $plan {
            $(plan if plan == $list[$k] => {
                const $p: u32 = $list[$k];
                $body
            })*
            _ => {
                const $p: u32 = $crate::solver::scheme::plan::RUNTIME;
                $body
            }
        }
    }};
}
pub(crate) use with_plan;

/// [`with_plan!`] over [`ACCELERATIONS`] (pass B).
macro_rules! with_accelerations_plan {
    ($plan:expr, $p:ident => $body:expr) => {
        $crate::solver::scheme::plan::with_plan!(
            $crate::solver::scheme::plan::ACCELERATIONS; $plan, $p => $body; 0 1 2 3 4 5 6 7 8 9 10 11 12 13 14 15 16
        )
    };
}
pub(crate) use with_accelerations_plan;

/// [`with_plan!`] over [`RATES`] (pass A).
macro_rules! with_rates_plan {
    ($plan:expr, $p:ident => $body:expr) => {
        $crate::solver::scheme::plan::with_plan!($crate::solver::scheme::plan::RATES; $plan, $p => $body; 0 1 2 3)
    };
}
pub(crate) use with_rates_plan;
