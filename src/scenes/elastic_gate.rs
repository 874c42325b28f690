//! Water released through an elastic gate (Antoci, Gallati & Sibilla 2007, "Numerical
//! simulation of fluid-structure interaction by SPH", Computers & Structures 85): beyond the
//! thesis, the FSI benchmark SPH codes validate against. Water `column_width` = 0.1 m wide
//! and `column_height` = 0.14 m high at the left of a tank is held by a rubber gate
//! `gate_thickness` = 0.005 m thick and `gate_length` = 0.079 m long standing on the floor
//! to the water's right, clamped at its top to a rigid wall that holds the water above it
//! and free at its lower end; the floor runs on beyond the gate to the tank's far wall at
//! `tank_width` = 1 m, so far that the water released does not come back from it before
//! t = 0.4 s, the measurement's end. The gate's material is that of the CTVF authors' reproduction
//! (github.com/dineshadepu/fsi_etvf, `ng_2020_elastic_dam_break.py`, after Ng et al. 2020
//! and Antoci et al. 2007): rho = 1100 kg/m^3, E = 11.96 MPa (a shear modulus of 4.27 MPa
//! at nu = 0.4), nu = 0.4. The fluid is the CTVF fluid of the dam break (EDAC pressure,
//! continuity density, Sun shifting, artificial viscosity `alpha` = 0.05 as that script
//! runs it), c0 = 10 sqrt(2 g H); the gate the CTVF solid with IPST, under gravity,
//! stepping `solid_substeps` times per fluid step (its sound speed, 135 m/s, is about eight
//! times the water's).
//!
//! The gate is a lattice of `round(gate_thickness / dx)` x `round(gate_length / dx)`
//! particles from the floor up; the rigid wall above it is fixed particles of the same body
//! continuing its columns up to the tank's top (its clamp and the wall the water leans on
//! above the gate).
//!
//! `tip_x`, `tip_y`: the displacement of the gate's free end (the mean of its lowest row)
//! from its start (m). Metrics: `tip_x_max`, `tip_y_max` (m), the largest over the run;
//! `tip_x_rms`, `tip_y_rms`, the RMS deviation from Antoci et al.'s measured free-end
//! displacements at their times within the run (m); `clusters_max`, `max_gap`, the gate's
//! numerical fracture (particles linked within 1.5 dx; 1 cluster: intact); `particles_lost`,
//! water particles
//! beyond the outer layer of the tank's walls or inside the gate, at the end or at any sample
//! before it.
//! `timeseries.csv`: `t, tip_x, tip_y, max_speed`.

use super::fluid_scheme::{free_surface_params, scheme_params};
use super::fsi_common::{
    check_lattice, fsi_setup, lattice_words, reference_curve, structure_params, FsiSetup, StructureRun, Watch,
};
use super::geometry::lattice;
use super::params::{Bound, Params, Spec};
use super::solid_common::{Probe, SolidDefaults};
use super::tank::{Column, G, LAYERS};
use super::walls::wall_params;
use super::{common_params, SceneEntry, SceneRun};
use crate::solver::nnps::Domain;

const ANTOCI: &str = include_str!("../../reference_data/antoci2007_gate_tip_displacement.csv");

/// The gate's body name.
const GATE: &str = "gate";

/// The registry entry.
pub const ENTRY: SceneEntry = SceneEntry {
    name: "elastic_gate",
    dim: 2,
    about: "Water released through an elastic rubber gate (Antoci, Gallati & Sibilla 2007)",
    params,
    build,
    check: |p| setup(p).map(drop),
    metrics: &[
        "tip_x_max",
        "tip_y_max",
        "tip_x_rms",
        "tip_y_rms",
        "particles_lost",
        "clusters_max",
        "max_gap",
    ],
    columns: &["t", "tip_x", "tip_y", "max_speed"],
    outputs: 0,
};

/// The two lengths the structure's lattice spans, for its particle count and its errors.
const LATTICE: (&str, &str) = ("gate_thickness", "tank_height");

fn params() -> Vec<Spec> {
    let mut v = vec![
        Spec::float("dx", 0.001, Bound::Positive, "particle spacing of water and gate (m)"),
        Spec::float(
            "column_width",
            0.1,
            Bound::Positive,
            "water column width (m), from the left wall to the gate",
        ),
        Spec::float("column_height", 0.14, Bound::Positive, "water column height H (m)"),
        Spec::float("gate_thickness", 0.005, Bound::Positive, "gate thickness (m)"),
        Spec::float("gate_length", 0.079, Bound::Positive, "gate length from the floor to its clamp (m)"),
        Spec::float("tank_width", 1.0, Bound::Positive, "tank width (m): the floor beyond the gate"),
        Spec::float(
            "tank_height",
            0.16,
            Bound::Positive,
            "tank wall height (m), the rigid wall above the gate's too",
        ),
        Spec::float("alpha", 0.05, Bound::NonNegative, "the water's artificial viscosity alpha, eq. (28)"),
    ];
    v.extend(scheme_params("sun"));
    v.extend(free_surface_params());
    v.extend(wall_params());
    v.extend(structure_params(&SolidDefaults {
        dx: 0.001,
        youngs_modulus: 11.958923292360354e6,
        poisson_ratio: 0.4,
        density: 1100.0,
        yield_stress: None,
        alpha: 1.0,
        pst: "ipst",
    }));
    v.extend(common_params(0.4));
    v
}

fn column(p: &Params) -> Column {
    let tank = (p.float("tank_width"), p.float("tank_height"));
    Column { width: p.float("column_width"), height: p.float("column_height"), tank, dx: p.float("dx") }
}

const KEYS: [&str; 4] = ["column_width", "column_height", "tank_width", "tank_height"];

fn setup(p: &Params) -> Result<FsiSetup, String> {
    let scene = "elastic_gate";
    let bad = |key: &str, why: String| Err(format!("scene `{scene}`: `{key}` = {}: {why}", p.float(key)));
    let (l, hc) = (p.float("column_width"), p.float("column_height"));
    let (t, gl) = (p.float("gate_thickness"), p.float("gate_length"));
    let (tw, th, dx) = (p.float("tank_width"), p.float("tank_height"), p.float("dx"));
    if l + t > tw {
        return Err(format!(
            "scene `{scene}`: `column_width` = {l:?} and `gate_thickness` = {t:?} put the gate's far face at x = {:?}, beyond the tank (`tank_width` = {tw:?})",
            l + t
        ));
    }
    if th < hc {
        return bad("tank_height", format!("the tank is lower than the column (column_height = {hc})"));
    }
    if gl >= hc {
        return bad(
            "gate_length",
            format!("the gate is as high as the water (column_height = {hc}): nothing holds it above"),
        );
    }
    for key in ["gate_thickness", "gate_length"] {
        if p.float(key) < 2.0 * dx {
            return bad(
                key,
                format!("the gate needs at least two particles across it and along it (dx = {dx})"),
            );
        }
    }
    check_lattice(scene, p, LATTICE)?;
    // The free end swings at most at the water's outflow speed, sqrt(2 g H).
    let u = (2.0 * G * hc).sqrt();
    fsi_setup(scene, p, (&column(p), KEYS), (u, "`column_height`"), G)
}

fn build(p: &Params) -> Result<Box<dyn SceneRun>, String> {
    Ok(Box::new(gate(p)?))
}

fn gate(p: &Params) -> Result<StructureRun, String> {
    let s = setup(p)?;
    let (dx, l, t, gl) =
        (p.float("dx"), p.float("column_width"), p.float("gate_thickness"), p.float("gate_length"));
    let (tw, th) = (p.float("tank_width"), p.float("tank_height"));
    let (fluid, wall) = column(p).bodies(p, s.h, s.constants.c0, s.fluid, G)?;
    let free = lattice(l, l + t, 0.0, gl, dx);
    let fixed = lattice(l, l + t, gl, th, dx);
    let gate = s.structure(("elastic_gate", &lattice_words(p, LATTICE)), GATE, free, fixed, p)?;
    let tip = Probe::new(&gate, "the gate's free end", |x| x[1] < dx)?;
    // Open above: the water running back up the left wall splashes over it; a tank width
    // on either side and eight water heights above (as the dam break's box).
    let edge = (LAYERS as f64 + 1.0) * dx;
    let domain = Domain::bounded([-tw, -edge], [2.0 * tw, th + 8.0 * p.float("column_height")]);
    let sim = s.simulation("elastic_gate", p, domain, [fluid.into(), wall.into(), gate.into()])?;
    let watch = Watch::new(GATE, tip, (tw, dx));
    Ok(StructureRun {
        sim,
        watch,
        published: vec![("tip_x_rms", 0, measured("x")), ("tip_y_rms", 1, measured("y"))],
        held: "the gate clamped to a rigid wall above it",
    })
}

/// Antoci et al.'s measured free-end displacement, component `x` or `y`.
fn measured(component: &str) -> Vec<(f64, f64)> {
    reference_curve(ANTOCI, (1, component), (2, 3))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_measured_curves_parse() {
        let (x, y) = (measured("x"), measured("y"));
        assert_eq!((x.len(), y.len()), (9, 10));
        assert!(x.iter().map(|s| s.1).fold(0.0, f64::max) > 0.04);
        assert!(y.iter().map(|s| s.1).fold(0.0, f64::max) > 0.01);
    }
}
