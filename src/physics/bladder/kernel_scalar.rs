//! The kernel's two number types as [`KernelScalar`]s: [`Dual`] on the hot path (its node sums
//! vectorized), [`HyperDual`] for the second-order partials.

use super::continuum::{dual_node_sums, KernelScalar, WallCall, WallNode, WallSums};
use crate::physics::numerics::dual::Dual;
use crate::physics::numerics::hyper_dual::HyperDual;

impl KernelScalar for Dual {
    #[inline]
    fn constant(v: f64) -> Self {
        Dual::constant(v)
    }
    #[inline]
    fn value(self) -> f64 {
        self.v
    }
    #[inline]
    fn recip(self) -> Self {
        Dual::recip(self)
    }
    #[inline]
    fn ln(self) -> Self {
        Dual::ln(self)
    }
    #[inline]
    fn exp(self) -> Self {
        Dual::exp(self)
    }
    #[inline]
    fn rsqrt(self) -> Self {
        Dual::rsqrt(self)
    }
    #[inline]
    fn sqrt(self) -> Self {
        Dual::sqrt(self)
    }
    /// Vectorized across the nodes: the hot path.
    #[inline]
    fn wall_sums(nodes: &[WallNode], call: &WallCall<Self>) -> Option<WallSums<Self>> {
        dual_node_sums(nodes, call)
    }
}

impl KernelScalar for HyperDual {
    fn constant(v: f64) -> Self {
        HyperDual::constant(v)
    }
    fn value(self) -> f64 {
        self.v
    }
    fn recip(self) -> Self {
        HyperDual::recip(self)
    }
    fn ln(self) -> Self {
        HyperDual::ln(self)
    }
    fn exp(self) -> Self {
        HyperDual::exp(self)
    }
    fn rsqrt(self) -> Self {
        HyperDual::rsqrt(self)
    }
    fn sqrt(self) -> Self {
        HyperDual::sqrt(self)
    }
}
