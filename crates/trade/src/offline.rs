//! The offline truth and baseline on the CPU: the real scene path traced with the object in it
//! (what a photograph with a real object would show), and Debevec's (1998) differential
//! rendering with the reconstructed model: L_final = L_photo + L_obj - L_noobj outside the
//! object, L_obj on it.

use differential_composite::{CompositeError, SyntheticObject};
use envmap_sphere::EnvMap;
use glam::Vec3;
use real_scene::RealScene;

use crate::capture::{PhotoSettings, photograph, photograph_with};

/// The real scene photographed with `object` in it (HDR, row-major).
///
/// # Errors
/// The photograph's errors (a map missing for an environment-lit scene, or given for another).
pub fn truth(
    real: &RealScene,
    object: &SyntheticObject,
    map: Option<&EnvMap>,
    settings: &PhotoSettings,
) -> Result<Vec<Vec3>, CompositeError> {
    Ok(photograph_with(real, &[object.to_object()], map, settings)?.color)
}

/// Debevec's differential rendering: `photo` plus the model rendered with the object minus the
/// model rendered without it, both path traced with `settings` (the same seed, so their noise
/// cancels where the object changes nothing); the object's own render where it is seen.
///
/// # Errors
/// As [`truth`].
pub fn debevec(
    model: &RealScene,
    object: &SyntheticObject,
    map: Option<&EnvMap>,
    photo: &[Vec3],
    settings: &PhotoSettings,
) -> Result<Vec<Vec3>, CompositeError> {
    let with = photograph_with(model, &[object.to_object()], map, settings)?;
    let without = photograph(model, map, settings)?;
    if photo.len() != with.color.len() {
        return Err(CompositeError::Parameter(format!(
            "the photograph has {} pixels, the model's camera {}",
            photo.len(),
            with.color.len()
        )));
    }
    let object_id = model.patches.len() as u32;
    let on_object = |k: usize| with.object_id.get(k) == Some(&object_id);
    Ok((0..photo.len())
        .map(
            |k| {
                if on_object(k) { with.color[k] } else { (photo[k] + with.color[k] - without.color[k]).max(Vec3::ZERO) }
            },
        )
        .collect())
}
