//! The closed loop: what the paper's model leaves in the residual, which recorded or derived
//! quantity explains it, and the model extended with that effect, judged on activations that took
//! part in neither the fit nor the choice.
//!
//! One way through, for one unit ([`closing::close`]): activations by role ([`roles`]) → stage 3's
//! lookup and the initial bias chosen per axis ([`keying`], [`warm_start`]) → the diagnosis of the
//! residual ([`diagnose`], over [`candidates`] with what the tables absorb taken out, [`absorb`],
//! selected forward by [`selection`]) →
//! extra terms ([`extend`], with the temperature-rate filter's start from [`switch_on_rate`]) →
//! the error before and after on held-out activations.

pub mod absorb;
pub mod activations;
pub mod before_after;
pub mod candidates;
pub mod closing;
pub mod diagnose;
pub mod extend;
pub mod gram;
pub mod keying;
pub mod permutation;
pub mod roles;
pub mod selection;
pub mod statistics;
pub mod switch_on_rate;
pub mod warm_start;
