//! Each instant's camera position relative to its target where the
//! timeline writes digits: f64 cannot subtract them, so the difference is
//! taken in high precision (`crate::exact::difference`), once per
//! instant however often the instant's scene is built (validation, `info`,
//! the plan, the frame hashes), and carried in the camera's `offset`.

use crate::camera::Camera;
use crate::math::{DVec3, Real};
use std::collections::HashMap;
use std::sync::{Arc, Mutex};

/// Relative positions by instant (the bits of its time), kept by a
/// timeline and the copies of it whose cameras move the same.
#[derive(Clone, Debug, Default)]
pub(super) struct Relatives(Arc<Mutex<HashMap<u64, DVec3>>>);

impl Relatives {
    /// Sets `camera.offset` to its position relative to its target at
    /// `time_seconds`, where the position or target has digits and nothing
    /// placed it yet: computed once, then kept.
    pub(super) fn carry(&self, time_seconds: Real, camera: &mut Camera) {
        let digits = camera.position_digits.is_some() || camera.target_digits.is_some();
        if camera.offset.is_some() || !digits {
            return;
        }
        let key = time_seconds.to_bits();
        // A panic elsewhere while holding the lock leaves whole entries.
        let lock = || self.0.lock().unwrap_or_else(|e| e.into_inner());
        let kept = lock().get(&key).copied();
        let relative = kept.unwrap_or_else(|| {
            let relative = camera.relative_position();
            lock().insert(key, relative);
            relative
        });
        camera.offset = Some(relative);
    }
}
