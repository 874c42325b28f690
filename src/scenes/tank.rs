//! A water column at rest in an open tank of wall particles, under gravity: how the dam break
//! (a column narrower than its tank) and the hydrostatic tank (a column as wide) start.
//! rho0 = 1000 kg/m^3, g = 9.81 m/s^2, three wall layers, c0 = 10 sqrt(2 g H) and
//! continuity density ([`FluidConstants::under_gravity`]), the fluid at the hydrostatic
//! pressure `rho0 g (H - y)`.

use super::fluid_scheme::{fluid_scheme, require_free_surface_scheme, FluidConstants};
use super::geometry::{box_walls, lattice};
use super::memory::check_size;
use super::params::Params;
use super::walls::{
    check_wall_layers, fluid_at_rest, wall_density, wall_from, wall_pressure, wall_viscosity,
};
use crate::solver::kernel::Kernel;
use crate::solver::math::Vector;
use crate::solver::scheme::FluidScheme;
use crate::solver::systems::{Fluid, Wall};

/// Water's density (kg/m^3).
pub const RHO0: f64 = 1000.0;
/// Gravity (m/s^2).
pub const G: f64 = 9.81;
/// Wall layers around the tank.
pub const LAYERS: usize = 3;

/// The column `[0, width] x [0, height]` in an open tank `tank = (width, height)` with its
/// corner at the origin, particles `dx` apart.
pub struct Column {
    /// The column's width (m),
    pub width: f64,
    /// its height H (m),
    pub height: f64,
    /// the tank's inner width and height (m),
    pub tank: (f64, f64),
    /// and the particle spacing (m).
    pub dx: f64,
}

impl Column {
    /// The constants, kernel, smoothing length and scheme of scene `scene`, once the checks
    /// every tank makes have passed (after the scene's own checks of its geometry): a
    /// column at least four particles wide and high (`keys` name its width and height
    /// among the parameters `p`, then the parameters the tank's size comes from), a
    /// free-surface scheme, a size that fits, enough wall layers for the kernel.
    pub fn setup(
        &self,
        scene: &str,
        keys: [&str; 4],
        p: &Params,
    ) -> Result<(FluidConstants, Kernel, f64, FluidScheme), String> {
        let Self { width, height, tank: (tw, th), dx } = *self;
        let [width_key, height_key, ..] = keys;
        for (key, len) in [(height_key, height), (width_key, width)] {
            if len < 4.0 * dx {
                return Err(format!(
                    "scene `{scene}`: `{key}` = {len} is less than 4 particle spacings (dx = {dx})"
                ));
            }
        }
        require_free_surface_scheme(scene, p)?;
        let walls = (tw + 2.0 * th) / dx * LAYERS as f64;
        // Named with the lengths the count comes from: any of them may be the one that is off.
        let mut lengths: Vec<String> = Vec::new();
        for key in keys.iter().filter(|k| p.0.contains_key(**k)) {
            let named = format!("`{key}` = {}", p.float(key));
            if !lengths.contains(&named) {
                lengths.push(named);
            }
        }
        let size = format!("{dx} ({})", lengths.join(", "));
        check_size::<2>(scene, "dx", size, (width / dx) * (height / dx) + walls)?;
        let constants = FluidConstants::under_gravity(RHO0, G, height, dx, p.float("alpha"));
        let (kernel, h, scheme) = fluid_scheme::<2>(scene, p, &constants)?;
        check_wall_layers(scene, p, &kernel, h, dx, LAYERS)?;
        Ok((constants, kernel, h, scheme))
    }

    /// The fluid of `physics` at the hydrostatic pressure of gravity `g` (smoothing length
    /// `h`) and the tank's walls (with the wall models `p` asks for).
    pub fn bodies(
        &self,
        p: &Params,
        h: f64,
        c0: f64,
        physics: FluidScheme,
        g: f64,
    ) -> Result<(Fluid<2>, Wall<2>), String> {
        self.bodies_without(p, (h, c0, physics, g), |_| false)
    }

    /// As [`bodies`](Self::bodies), without the wall particles where `removed` (where a
    /// structure takes the wall's place: a plate as the tank's floor, a clamp through it).
    pub fn bodies_without(
        &self,
        p: &Params,
        (h, c0, physics, g): (f64, f64, FluidScheme, f64),
        removed: impl Fn(&Vector<2>) -> bool,
    ) -> Result<(Fluid<2>, Wall<2>), String> {
        let Self { width, height, tank: (tw, th), dx } = *self;
        let hydrostatic = |x: &Vector<2>| RHO0 * g * (height - x[1]);
        let fluid = fluid_at_rest(lattice(0.0, width, 0.0, height, dx), dx, RHO0, h, physics, hydrostatic)?;
        let mut walls = box_walls(tw, th, dx, LAYERS, false);
        walls.retain(|(x, _)| !removed(x));
        let wall = wall_from(&walls, |_| Vector::zeros(), dx, RHO0, c0)?.with_models(
            wall_density(p),
            wall_pressure(p),
            wall_viscosity(p),
        );
        Ok((fluid, wall))
    }
}
