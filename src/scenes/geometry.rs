//! Particle lattices and wall layers shared by the scenes.

use crate::solver::math::Vector;

/// Cell-centred lattice points of spacing `dx` filling `[x0, x1] x [y0, y1]`.
pub fn lattice(x0: f64, x1: f64, y0: f64, y1: f64, dx: f64) -> Vec<Vector<2>> {
    let nx = ((x1 - x0) / dx).round() as usize;
    let ny = ((y1 - y0) / dx).round() as usize;
    let mut v = Vec::with_capacity(nx * ny);
    for j in 0..ny {
        for i in 0..nx {
            v.push(Vector::<2>::new(x0 + (i as f64 + 0.5) * dx, y0 + (j as f64 + 0.5) * dx));
        }
    }
    v
}

/// `layers` layers of wall particles around the box `[0, w] x [0, h]` on the lattice of
/// the fluid (spacing `dx`), on the sides listed (`top` adds the lid row). Each particle
/// comes with its unit normal: the direction to the nearest point of the box.
pub fn box_walls(w: f64, h: f64, dx: f64, layers: usize, top: bool) -> Vec<(Vector<2>, Vector<2>)> {
    let nx = (w / dx).round() as i64;
    let ny = (h / dx).round() as i64;
    let l = layers as i64;
    let jmax = if top { ny + l } else { ny };
    let mut out = Vec::new();
    for j in -l..jmax {
        for i in -l..nx + l {
            let inside = (0..nx).contains(&i) && (0..ny).contains(&j);
            if inside {
                continue;
            }
            let x = Vector::<2>::new((i as f64 + 0.5) * dx, (j as f64 + 0.5) * dx);
            let nearest = Vector::<2>::new(x[0].clamp(0.0, w), x[1].clamp(0.0, h));
            let n = (nearest - x).normalize();
            out.push((x, n));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn walls_surround_the_box_with_inward_normals() {
        let (w, h, dx) = (1.0, 0.5, 0.1);
        let walls = box_walls(w, h, dx, 3, true);
        // (10 + 6) x (5 + 6) minus the 10 x 5 fluid cells.
        assert_eq!(walls.len(), 16 * 11 - 50);
        for (x, n) in &walls {
            assert!((n.norm() - 1.0).abs() < 1e-12);
            // One step along the normal approaches the box.
            let d0 = (x - Vector::<2>::new(x[0].clamp(0.0, w), x[1].clamp(0.0, h))).norm();
            let y = x + n * 0.01;
            let d1 = (y - Vector::<2>::new(y[0].clamp(0.0, w), y[1].clamp(0.0, h))).norm();
            assert!(d1 < d0);
        }
        let open = box_walls(w, h, dx, 3, false);
        assert!(open.iter().all(|(x, _)| x[1] < h));
        assert_eq!(lattice(0.0, w, 0.0, h, dx).len(), 50);
    }
}
