//! The layered walls (`bladder_model` 1, 2, 4, 5): the layer recursion of eq. 2.19-2.20, each
//! layer's stresses from the axial stretch and the outer diameter, and the free bladder's axial
//! force summed from the outside in where a vacuum has pulled the bore in.

use super::{Bladder, InnerLayer, Kernel, KernelScalar, Layer, SleeveGeometry, Wall};
use crate::physics::numerics::dual::Dual;

impl<S: SleeveGeometry> Bladder<S> {
    /// The layer recursion of eq. 2.19-2.20 at muscle length `l` and bladder outer diameter `x`:
    /// as written (`as_written`, `sigma_33 = -p_in` in eq. 2.12) or with each layer balanced by
    /// its stress difference (`sigma_33 = 0`). `None` if a layer's squared hoop stretch is not
    /// positive (outside the geometry) or not finite.
    #[inline]
    pub(super) fn layered_kernel<T: KernelScalar>(
        &self,
        pressure: f64,
        l: T,
        x: T,
        as_written: bool,
    ) -> Option<Kernel<T>> {
        let stretch = self.stretch(l, x);
        let inv_l = l.recip();
        // Pressure inside the current layer is a P - c (linear in P, a > 0), so the threshold
        // pressure c/a of the whole stack falls out of the same pass.
        let mut a = T::constant(1.0);
        let mut c = T::constant(0.0);
        // Eq. 2.17 summed over the layers, sigma_11 = axial - p_in with p_in = a P - c: the
        // rubber's axial force is (sum (axial + c) V_i - P sum a V_i) / L, affine in P.
        let mut axial_sum = T::constant(0.0);
        let mut a_sum = T::constant(0.0);
        let mut inner: Option<InnerLayer<T>> = None;
        for layer in &self.layers {
            let LayerStress {
                l2_sq,
                hoop,
                axial,
                k,
            } = stretch.layer(layer)?;
            // sigma_33 = -p_in; sigma_11 = sigma_33 + axial (eq. 2.17 for the layer).
            axial_sum = axial_sum + (axial + c) * layer.rubber_volume;
            a_sum = a_sum + a * layer.rubber_volume;
            if inner.is_none() {
                inner = Some(InnerLayer { l2_sq, axial, hoop });
            }
            if as_written {
                // Eq. 2.12 for the layer: p_out = p_in - sigma_22 k with sigma_22 = -p_in + hoop.
                let one_k = k + 1.0;
                c = c * one_k + hoop * k;
                a = a * one_k;
            } else {
                // The layer's balance with its stress difference: p_out = p_in - hoop k (the
                // first-order term p_out (d_out - d_in) of eq. 2.10 no longer dropped).
                c = c + hoop * k;
            }
        }
        let inner = inner?;
        let p_eff = a * pressure - c;
        let threshold = c.value() / a.value();
        let elastic = (axial_sum - a_sum * pressure) * inv_l;
        Some(Kernel {
            a,
            c,
            p_eff,
            threshold,
            elastic,
            elastic_dp: [a_sum, inv_l],
            inner,
        })
    }

    /// The layered walls' elastic force at a free root `k` (eq. 2.17 summed over the layers),
    /// with the outer layers' pressures taken from the outside in, from the free bladder's
    /// `P_eff = 0`: `p_in = (p_out + hoop k) / (1 + k)` of eq. 2.19 (`p_in = p_out + hoop k` for
    /// the balanced layers), and the innermost layer's the gas's `P`. At the exact root the
    /// outward recursion gives the same pressures; but a bore pulled nearly closed by a vacuum
    /// multiplies them by the innermost layer's `1 + k` (millions), so a root known to rounding
    /// leaves them, and the force, wrong by newtons, where inwards each step divides by it.
    /// With the innermost layer's rubber volume (its `-P V_1 / L` is the only term moving with
    /// `P` at fixed `(L, x)`). `None` for the quadrature walls, or outside the geometry.
    pub(super) fn free_layers_elastic(
        &self,
        pressure: f64,
        l: Dual,
        x: Dual,
        k: &Kernel,
    ) -> Option<(Dual, f64)> {
        let as_written = match self.wall {
            Wall::Layers(_) => false,
            Wall::DissertationLayers(_) => true,
            Wall::Exact(_) | Wall::DissertationContinuum(_) => return None,
        };
        let stretch = self.stretch(l, x);
        let (innermost, outer) = self.layers.split_first()?;
        let mut sum = (k.inner.axial + (-pressure)) * innermost.rubber_volume;
        let mut p_out = Dual::constant(0.0);
        for layer in outer.iter().rev() {
            let LayerStress { hoop, axial, k, .. } = stretch.layer(layer)?;
            let p_in = if as_written {
                (p_out + hoop * k) * (k + 1.0).recip()
            } else {
                p_out + hoop * k
            };
            sum = sum + (axial - p_in) * layer.rubber_volume;
            p_out = p_in;
        }
        let elastic = sum * l.recip();
        elastic
            .v
            .is_finite()
            .then_some((elastic, innermost.rubber_volume))
    }
}

/// The axial stretch's powers, the Mooney-Rivlin constants and the squared outer diameter at
/// `(L, x)`, from which every layer's stresses follow ([`Stretch::layer`]).
struct Stretch<T> {
    c1x2: f64,
    c2x2: f64,
    inv_lambda1: T,
    lambda1_sq: T,
    inv_lambda1_sq: T,
    x_sq: T,
}

/// One layer's squared hoop stretch, its hoop and axial stress differences and eq. 2.19's `k`.
struct LayerStress<T> {
    l2_sq: T,
    hoop: T,
    axial: T,
    k: T,
}

impl<S: SleeveGeometry> Bladder<S> {
    #[inline(always)]
    fn stretch<T: KernelScalar>(&self, l: T, x: T) -> Stretch<T> {
        let lambda1 = l * (1.0 / self.tube.unstretched_length);
        let inv_lambda1 = lambda1.recip();
        Stretch {
            c1x2: 2.0 * self.tube.mooney_c1,
            c2x2: 2.0 * self.tube.mooney_c2,
            inv_lambda1,
            lambda1_sq: lambda1 * lambda1,
            inv_lambda1_sq: inv_lambda1 * inv_lambda1,
            x_sq: x * x,
        }
    }
}

impl<T: KernelScalar> Stretch<T> {
    /// The layer's stresses; `None` if its squared hoop stretch is not positive (outside the
    /// geometry) or not finite.
    #[inline(always)]
    fn layer(&self, layer: &Layer) -> Option<LayerStress<T>> {
        // Eq. 2.20 in squared form: lambda_2i^2 = (x^2 - (D_RO^2 - D_0i^2)/lambda_1) / D_0i^2.
        let l2_sq = (self.x_sq - self.inv_lambda1 * layer.excess_sq) * layer.inv_d0_sq;
        if !(l2_sq.value() > 0.0 && l2_sq.value().is_finite()) {
            return None;
        }
        let inv_l2_sq = l2_sq.recip();
        let l3_sq = self.inv_lambda1_sq * inv_l2_sq;
        let inv_l3_sq = self.lambda1_sq * l2_sq;
        // Eq. 2.9b and 2.9a without the radial stress.
        let hoop = (l2_sq - l3_sq) * self.c1x2 - (inv_l2_sq - inv_l3_sq) * self.c2x2;
        let axial =
            (self.lambda1_sq - l3_sq) * self.c1x2 - (self.inv_lambda1_sq - inv_l3_sq) * self.c2x2;
        Some(LayerStress {
            l2_sq,
            hoop,
            axial,
            // lambda_3 / lambda_2 * Delta D / D_0i of eq. 2.19.
            k: self.inv_lambda1 * inv_l2_sq * layer.wall_ratio,
        })
    }
}
