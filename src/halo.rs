//! Halo parameters (paper 000, eq. 2-3).
//!
//! A projected surface is thickened into a halo of half-width `rho` along its normal; inside
//! the halo the depth grows from the surface's w-depth d_orig as
//! d_new = d_orig + max(0, |2t - 1| - delta_t) delta_d, where t runs from 0 on the negative
//! offset surface to 1 on the positive one.

use serde::{Deserialize, Serialize};

/// The parameters of the volumetric halos of a scene.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct HaloParams {
    /// Half-width of the halo, relative to the diagonal of the projected scene's bounding box.
    pub rho: f64,
    /// Depth increment delta_d at the halo's outer surfaces (eq. 3), in w units.
    pub delta_d: f64,
    /// Dead zone delta_t in [0, 1) of |2t - 1| before the depth starts to grow (eq. 3).
    pub delta_t: f64,
}

impl Default for HaloParams {
    fn default() -> Self {
        HaloParams {
            rho: 0.01,
            delta_d: 0.5,
            delta_t: 0.1,
        }
    }
}

impl HaloParams {
    /// Checks the numbers: `Err((field, message))` names the first bad one.
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        if !(self.rho.is_finite() && self.rho > 0.0 && self.rho < 0.5) {
            return Err((
                "rho",
                format!(
                    "must be greater than 0 and less than 0.5 (a share of the scene's diagonal), got {}",
                    self.rho
                ),
            ));
        }
        if !(self.delta_d.is_finite() && self.delta_d >= 0.0) {
            return Err((
                "delta_d",
                format!(
                    "must be a finite number of at least 0, got {}",
                    self.delta_d
                ),
            ));
        }
        if !(self.delta_t.is_finite() && (0.0..1.0).contains(&self.delta_t)) {
            return Err((
                "delta_t",
                format!("must be in [0, 1), got {}", self.delta_t),
            ));
        }
        Ok(())
    }
}
