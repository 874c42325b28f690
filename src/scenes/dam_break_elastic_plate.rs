//! A dam break onto an elastic plate (thesis sec. 4.3.3, figs. 4.6-4.8; Walhorn et al. 2005,
//! Idelsohn et al. 2008, Sun et al. 2019): a water column 0.146 m wide and 0.292 m high at
//! the left of a tank 0.584 m wide and `tank_height` = 0.32 m high (three wall layers, open
//! above) is released onto an elastic plate 0.012 m wide and 0.08 m high standing on the
//! floor at the tank's middle (x = 0.292), clamped at its foot (rho = 2500 kg/m^3,
//! E = 1 MPa, nu = 0). The geometry is the literature's (the thesis gives it in its
//! fig. 4.6; its author's script places the plate 1.25 mm further right and narrows the
//! tank by 5.5 mm, an artefact of its tank builder). The fluid is the CTVF fluid of the dam
//! break (EDAC pressure, continuity density, Sun shifting, artificial viscosity `alpha` =
//! 0.1 as the author's script runs it), c0 = 10 sqrt(2 g H); the plate the CTVF solid with
//! IPST (thesis sec. 4.2.3) under gravity. Its sound speed (11.5 m/s) is below the water's
//! (23.9 m/s): with `solid_substeps` = auto it steps with the fluid.
//!
//! The plate is a lattice of `round(plate_width / dx)` x `round(plate_height / dx)` particles
//! on the floor (y >= 0); its clamp continues its columns through the floor for as many
//! layers as the kernel's support reaches, fixed, in place of the floor's wall particles
//! there.
//!
//! `tip_x`, `tip_y`: the displacement of the plate's top row (the mean of its particles)
//! from its start (m). Metrics: `tip_x_max`, the largest `tip_x` over the run (m);
//! `tip_x_rms`, the RMS deviation of `tip_x` from Sun et al.'s (2019) MPS-DEM curve at its
//! times within the run (m); `tip_x_rms_bogaers`, the same against Bogaers et al.'s (2016)
//! QN-LS curve; `clusters_max`, `max_gap`, the plate's numerical fracture (particles linked
//! within 1.5 dx; 1 cluster: intact); `particles_lost`, water particles beyond the outer layer of the tank's walls or inside the plate, at the end or at any sample before it.
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
use crate::solver::math::Vector;
use crate::solver::nnps::Domain;

const SUN2019: &str =
    include_str!("../../reference_data/sun2019_elastic_plate_dambreak_tip_x_displacement.csv");

/// The plate's body name.
const PLATE: &str = "plate";

/// The registry entry.
pub const ENTRY: SceneEntry = SceneEntry {
    name: "dam_break_elastic_plate",
    dim: 2,
    about: "Dam break onto an elastic plate clamped to the floor (thesis sec. 4.3.3, Sun et al. 2019)",
    params,
    build,
    check: |p| setup(p).map(drop),
    metrics: &[
        "tip_x_max",
        "tip_x_rms",
        "tip_x_rms_bogaers",
        "particles_lost",
        "clusters_max",
        "max_gap",
        "tip_y_max",
    ],
    columns: &["t", "tip_x", "tip_y", "max_speed"],
    outputs: 0,
};

/// The two lengths the structure's lattice spans, for its particle count and its errors.
const LATTICE: (&str, &str) = ("plate_width", "plate_height");

fn params() -> Vec<Spec> {
    let mut v = vec![
        Spec::float("dx", 5e-4, Bound::Positive, "particle spacing of water and plate (m)"),
        Spec::float("column_width", 0.146, Bound::Positive, "water column width (m)"),
        Spec::float("column_height", 0.292, Bound::Positive, "water column height H (m)"),
        Spec::float("tank_width", 0.584, Bound::Positive, "tank width (m)"),
        Spec::float("tank_height", 0.32, Bound::Positive, "tank wall height (m)"),
        Spec::float(
            "plate_x",
            0.292,
            Bound::Positive,
            "the plate's centre line, from the tank's left wall (m)",
        ),
        Spec::float("plate_width", 0.012, Bound::Positive, "plate width (m)"),
        Spec::float("plate_height", 0.08, Bound::Positive, "plate height above the floor (m)"),
        Spec::float("alpha", 0.1, Bound::NonNegative, "the water's artificial viscosity alpha, eq. (28)"),
    ];
    v.extend(scheme_params("sun"));
    v.extend(free_surface_params());
    v.extend(wall_params());
    v.extend(structure_params(&SolidDefaults {
        dx: 5e-4,
        youngs_modulus: 1e6,
        poisson_ratio: 0.0,
        density: 2500.0,
        yield_stress: None,
        alpha: 1.0,
        pst: "ipst",
    }));
    v.extend(common_params(0.7));
    v
}

fn column(p: &Params) -> Column {
    let tank = (p.float("tank_width"), p.float("tank_height"));
    Column { width: p.float("column_width"), height: p.float("column_height"), tank, dx: p.float("dx") }
}

const KEYS: [&str; 4] = ["column_width", "column_height", "tank_width", "tank_height"];

/// The plate's x range.
fn plate_span(p: &Params) -> (f64, f64) {
    let (xc, w) = (p.float("plate_x"), p.float("plate_width"));
    (xc - 0.5 * w, xc + 0.5 * w)
}

fn setup(p: &Params) -> Result<FsiSetup, String> {
    let scene = "dam_break_elastic_plate";
    let bad = |key: &str, why: String| Err(format!("scene `{scene}`: `{key}` = {}: {why}", p.float(key)));
    let (l, tw, th) = (p.float("column_width"), p.float("tank_width"), p.float("tank_height"));
    let (x0, x1) = plate_span(p);
    let dx = p.float("dx");
    if tw < l {
        return bad("tank_width", format!("the tank is narrower than the column (column_width = {l})"));
    }
    if th < p.float("column_height") {
        return bad(
            "tank_height",
            format!("the tank is lower than the column (column_height = {})", p.float("column_height")),
        );
    }
    let plate = format!(
        "`plate_x` = {:?} and `plate_width` = {:?} put the plate from x = {x0:?} to {x1:?}",
        p.float("plate_x"),
        p.float("plate_width")
    );
    if x1 > tw {
        return Err(format!("scene `{scene}`: {plate}, beyond the tank (`tank_width` = {tw:?})"));
    }
    if x0 < l {
        return Err(format!("scene `{scene}`: {plate}, into the water column (`column_width` = {l:?})"));
    }
    for key in ["plate_width", "plate_height"] {
        if p.float(key) < 2.0 * dx {
            return bad(key, format!("the plate needs at least two particles across (dx = {dx})"));
        }
    }
    check_lattice(scene, p, LATTICE)?;
    // The plate's tip moves at most at the surge's speed, 2 sqrt(g H).
    let u = 2.0 * (G * p.float("column_height")).sqrt();
    fsi_setup(scene, p, (&column(p), KEYS), (u, "`column_height`"), G)
}

fn build(p: &Params) -> Result<Box<dyn SceneRun>, String> {
    Ok(Box::new(impact(p)?))
}

fn impact(p: &Params) -> Result<StructureRun, String> {
    let s = setup(p)?;
    let (dx, tw, th) = (p.float("dx"), p.float("tank_width"), p.float("tank_height"));
    let (x0, x1) = plate_span(p);
    let clamp = s.solid.support_layers() as f64 * dx;
    // The clamp takes the floor's place under the plate: the floor's particles there, so
    // that no gap opens between the two whatever the plate's offset from the floor's
    // lattice, and as many layers as the kernel's support reaches.
    let under_plate = |x: &Vector<2>| x[1] < 0.0 && x[0] > x0 - 1e-9 && x[0] < x1;
    let layers = s.solid.support_layers() as i64;
    let columns = ((x0 / dx - 0.5).ceil() as i64)..=((x1 / dx - 0.5).ceil() as i64 - 1);
    let fixed: Vec<Vector<2>> = (-layers..0)
        .flat_map(|j| {
            columns.clone().map(move |i| Vector::<2>::new((i as f64 + 0.5) * dx, (j as f64 + 0.5) * dx))
        })
        .filter(under_plate)
        .collect();
    let (fluid, wall) = column(p).bodies_without(p, (s.h, s.constants.c0, s.fluid, G), under_plate)?;
    let ph = p.float("plate_height");
    let free = lattice(x0, x1, 0.0, ph, dx);
    let plate =
        s.structure(("dam_break_elastic_plate", &lattice_words(p, LATTICE)), PLATE, free, fixed, p)?;
    let tip = Probe::new(&plate, "the plate's top", |x| x[1] > ph - dx)?;
    // Open above: the run-up jets rise far above the walls; a tank width on either side.
    let edge = (LAYERS as f64 + 1.0) * dx;
    let domain = Domain::bounded([-tw, -edge - clamp], [2.0 * tw, th + 8.0 * p.float("column_height")]);
    let sim =
        s.simulation("dam_break_elastic_plate", p, domain, [fluid.into(), wall.into(), plate.into()])?;
    let watch = Watch::new(PLATE, tip, (tw, dx));
    Ok(StructureRun {
        sim,
        watch,
        published: vec![
            ("tip_x_rms", 0, published("sun_2019_mps_dem")),
            ("tip_x_rms_bogaers", 0, published("bogaers_2016_qn_ls")),
        ],
        held: "the plate clamped through the floor",
    })
}

/// Sun et al.'s (2019) MPS-DEM curve of the tip's x displacement, or another `source` of
/// the reference file.
fn published(source: &str) -> Vec<(f64, f64)> {
    reference_curve(SUN2019, (0, source), (1, 2))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The coarse dam break (dx = 4 mm, 3 particles across the plate) with `solid_pst`
    /// in the plate to `tf`: at every hundredth of a second no water is inside the plate or
    /// beyond the walls; the tip has moved.
    fn water_stays_out(solid_pst: &str, tf: f64) {
        let specs = params();
        let mut p = Params::defaults(&specs);
        for (key, value) in [("dx", "0.004"), ("tf", &tf.to_string()), ("solid_pst", solid_pst)] {
            p.set_str("dam_break_elastic_plate", &specs, key, value).unwrap();
        }
        let mut run = impact(&p).unwrap();
        let mut t = 0.0;
        while t < tf - 1e-9 {
            t += 0.01;
            run.sim.advance(t, tf, |_| true).unwrap();
            run.sample();
            assert_eq!(run.watch.metrics(&run.sim, &[])["particles_lost"], 0.0, "water lost by t = {t}");
        }
        let tip = run.watch.seen.samples.iter().map(|s| s.1).fold(0.0, f64::max);
        assert!(tip > 0.005, "the water has pushed the plate's tip by at most {tip} m");
    }

    /// With IPST in the plate (the thesis's choice), through the impact (to t = 0.2 s, the
    /// plate's largest bend). Later in the quick preset's run, at this spacing, the plate's
    /// foot slides about one spacing over its clamp and one water particle follows it into
    /// the gap (the same without shifting in the plate): the problem's bound reports it.
    #[test]
    fn the_water_stays_out_of_the_plate_through_the_impact() {
        water_stays_out("ipst", 0.2);
    }

    /// With Sun's shifting in the plate, over the quick preset's whole run (t = 0.4 s: the
    /// impact, the plate's return and the water coming back from the far wall).
    #[test]
    fn with_sun_shifting_the_water_stays_out_to_the_end() {
        water_stays_out("sun", 0.4);
    }

    /// Bad input is refused with its key named.
    #[test]
    fn bad_input_is_refused_by_key() {
        let specs = params();
        for (key, value, named) in [
            ("plate_width", "0.6", "plate_width"),
            ("plate_width", "-0.012", "plate_width"),
            ("poisson_ratio", "0.5", "poisson_ratio"),
            ("solid_substeps", "0", "solid_substeps"),
            ("solid_substeps", "many", "solid_substeps"),
            ("plate_x", "0.1", "plate_x"),
        ] {
            let mut p = Params::defaults(&specs);
            let err = p
                .set_str("dam_break_elastic_plate", &specs, key, value)
                .and_then(|()| setup(&p).map(drop))
                .expect_err(&format!("{key} = {value} accepted"));
            assert!(err.contains(&format!("`{named}`")), "{key} = {value}: {err}");
        }
    }

    #[test]
    fn the_published_curves_parse() {
        let sun = published("sun_2019_mps_dem");
        assert_eq!(sun.len(), 90);
        assert!(sun.windows(2).all(|w| w[0].0 <= w[1].0));
        assert!(sun.iter().map(|s| s.1).fold(0.0, f64::max) > 0.04);
        assert_eq!(published("bogaers_2016_qn_ls").len(), 65);
    }
}
