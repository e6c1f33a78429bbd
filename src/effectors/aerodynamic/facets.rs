//! The surface that drag acts on when it is taken from `body.shape`: a box as six flat
//! facets, or a right circular cylinder integrated exactly.
//!
//! Each surface element of area dA, outward normal n̂ and position p (body axes, about the
//! hub's centre of mass) that faces the flow, n̂·ŵ > 0 with ŵ the direction of the
//! spacecraft's velocity through the air, takes the force −½ ρ |w|² C_d (n̂·ŵ) dA ŵ (the
//! flat-plate element of Basilisk's `facetDragDynamicEffector`; Markley & Crassidis,
//! *Fundamentals of Spacecraft Attitude Determination and Control*, 2014, §3.3.6.3). Every
//! element's force is along ŵ, so the whole surface is described, for a direction ŵ, by two
//! numbers:
//!
//! ```text
//! A_p(ŵ) = ∫ max(0, n̂·ŵ) dA          the projected (frontal) area, m²
//! M(ŵ)   = ∫ max(0, n̂·ŵ) p dA        its first moment, m³
//! ```
//!
//! and F = −½ ρ |w|² C_d A_p ŵ, τ = ∫ p × dF = −½ ρ |w|² C_d M × ŵ. The centre of pressure
//! M/A_p is defined up to a shift along ŵ, which changes no torque. Both shapes are convex, so
//! no element shades another.

use nalgebra::{UnitQuaternion, Vector3};
use std::f64::consts::PI;

/// A flat facet: one face of a polyhedron.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Facet {
    /// Outward unit normal (body axes).
    pub normal: Vector3<f64>,
    /// Area (m²).
    pub area: f64,
    /// Centroid (m, body axes, about the hub's centre of mass).
    pub centroid: Vector3<f64>,
}

/// A convex surface for drag, in body axes about the hub's centre of mass.
#[derive(Debug, Clone, PartialEq)]
pub enum DragSurface {
    /// The six faces of a box.
    Cuboid(Box<[Facet; 6]>),
    /// A right circular cylinder: its side and its two end caps, integrated exactly.
    Cylinder {
        /// Centre (m, body axes, about the hub's centre of mass).
        center: Vector3<f64>,
        /// Unit axis (body axes).
        axis: Vector3<f64>,
        /// Radius (m).
        radius: f64,
        /// Length (m).
        length: f64,
    },
}

impl DragSurface {
    /// A box of side lengths `size` (m) along the columns of `orientation` (body axes),
    /// centred at `center` (m): six facets, the faces ±x̂′ of area s_y s_z at ±(s_x/2) x̂′ from
    /// the centre, and so on.
    pub fn cuboid(
        size: Vector3<f64>,
        orientation: &UnitQuaternion<f64>,
        center: Vector3<f64>,
    ) -> Self {
        let face = |k: usize, sign: f64| {
            let (i, j) = ((k + 1) % 3, (k + 2) % 3);
            let normal = orientation * (sign * Vector3::ith(k, 1.0));
            Facet {
                normal,
                area: size[i] * size[j],
                centroid: center + 0.5 * size[k] * normal,
            }
        };
        DragSurface::Cuboid(Box::new([
            face(0, 1.0),
            face(0, -1.0),
            face(1, 1.0),
            face(1, -1.0),
            face(2, 1.0),
            face(2, -1.0),
        ]))
    }

    /// A cylinder of `radius` and `length` (m) whose axis is the local z of `orientation`
    /// (body axes), centred at `center` (m).
    pub fn cylinder(
        radius: f64,
        length: f64,
        orientation: &UnitQuaternion<f64>,
        center: Vector3<f64>,
    ) -> Self {
        DragSurface::Cylinder {
            center,
            axis: orientation * Vector3::z(),
            radius,
            length,
        }
    }

    /// The projected area A_p (m²) and its first moment M (m³, body axes, about the hub's
    /// centre of mass) for the unit direction `w_hat` of the spacecraft's velocity through
    /// the air.
    ///
    /// For the cylinder, with cos α = â·ŵ and sin α = |ŵ − cos α â|: the end cap facing the
    /// flow, of normal sgn(cos α) â, has area π r² |cos α| at its centre c + sgn(cos α) (L/2)
    /// â; the side, whose element at angle ψ from the meridian facing the flow has
    /// n̂·ŵ = sin α cos ψ on −π/2 < ψ < π/2, has ∫ = 2 r L sin α and first moment
    /// 2 r L sin α c + (π/2) r² L (ŵ − cos α â) (the lit half's centre of pressure is π r/4
    /// off the axis, towards the flow).
    #[inline]
    pub fn projection(&self, w_hat: &Vector3<f64>) -> (f64, Vector3<f64>) {
        match self {
            DragSurface::Cuboid(facets) => {
                let mut area = 0.0;
                let mut moment = Vector3::zeros();
                for f in facets.iter() {
                    let c = f.normal.dot(w_hat);
                    if c > 0.0 {
                        let a = f.area * c;
                        area += a;
                        moment += a * f.centroid;
                    }
                }
                (area, moment)
            }
            DragSurface::Cylinder {
                center,
                axis,
                radius,
                length,
            } => {
                let cos = axis.dot(w_hat);
                let across = w_hat - cos * axis;
                let sin = across.norm();
                let cap = PI * radius * radius * cos.abs();
                let side = 2.0 * radius * length * sin;
                let area = cap + side;
                let cap_center = center + (0.5 * length * cos.signum()) * axis;
                let moment = cap * cap_center
                    + side * center
                    + (0.5 * PI * radius * radius * length) * across;
                (area, moment)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The cuboid's faces: outward, of the right areas, with centroids on the faces.
    #[test]
    fn the_box_faces_are_outward_and_close_the_surface() {
        let q = UnitQuaternion::from_euler_angles(0.4, -0.7, 1.9);
        let c = Vector3::new(0.1, -0.2, 0.3);
        let DragSurface::Cuboid(faces) = DragSurface::cuboid(Vector3::new(1.0, 2.0, 3.0), &q, c)
        else {
            panic!("a box")
        };
        // A closed surface: Σ A n̂ = 0; the areas are 6, 3 and 2 m², twice each.
        let sum: Vector3<f64> = faces.iter().map(|f| f.area * f.normal).sum();
        assert!(sum.norm() < 1e-14, "{sum:?}");
        let total: f64 = faces.iter().map(|f| f.area).sum();
        assert!((total - 22.0).abs() < 1e-14);
        // Divergence theorem: Σ A (n̂·(centroid − c)) = 3 V = 18 m³.
        let flux: f64 = faces
            .iter()
            .map(|f| f.area * f.normal.dot(&(f.centroid - c)))
            .sum();
        assert!((flux - 18.0).abs() < 1e-13, "{flux}");
    }
}
