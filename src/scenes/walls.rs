//! Walls and the fluid at rest beside them: the wall parameters, a wall body from points, a
//! fluid at rest, and the check that the kernel stays within the walls' layers.

use super::params::{Params, Spec};
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::scheme::FluidScheme;
use crate::solver::systems::{Fluid, FluidInit, Wall, WallDensity, WallPressure, WallViscosity};

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
