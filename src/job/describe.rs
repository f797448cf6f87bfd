//! The render plan as `info` and the explorer show it: the effects a
//! scene enables and the stages each camera sample runs, with their cost.

use crate::scene::Scene;

/// The effects enabled, and which stages run per camera sample with their
/// cost in distance estimates.
pub fn plan_lines(base: &Scene) -> Vec<String> {
    let c = &base.camera;
    let mut lines = vec![format!(
        "camera:   {}{}",
        c.projection.describe(c.fov_degrees),
        c.stereo.map_or(String::new(), |s| format!(
            "; stereo {:?}, eyes {} of the camera–target distance apart",
            s.layout, s.eye_separation
        ))
    )];
    let effects = &base.effects;
    let enabled = effects.enabled();
    lines.push(format!(
        "effects:  {}",
        if enabled.is_empty() {
            "none enabled (baseline shading: Lambert light + ambient, orbit-trap colour)"
                .to_string()
        } else {
            enabled.join(", ")
        }
    ));
    // The render plan: which stages run per camera sample, and their cost in
    // distance estimates relative to marching (about 20 per ray at this size).
    let cones = match (base.cone_rays(), base.march_alone_reason()) {
        (1, Some(why)) => format!("each camera ray alone, {why}"),
        (1, None) => "each camera ray alone".to_string(),
        (n, _) => {
            let (columns, rows) = crate::march::cone_block(n);
            format!("blocks of {columns}×{rows} camera rays share a cone first")
        }
    };
    lines.push(format!(
        "plan:     per sample: primary march ({cones}); per hit: normal (4 estimates)"
    ));
    if let Some(sh) = &effects.shadows {
        lines.push(format!(
            "          + shadow march towards the light, up to {} estimates per lit hit ({})",
            sh.max_steps,
            if sh.softness > 0.0 {
                format!("soft, k = {}", sh.softness)
            } else {
                "hard".into()
            }
        ));
    }
    if let Some(ao) = &effects.ambient_occlusion {
        lines.push(format!(
            "          + ambient occlusion, {} estimates per hit",
            ao.samples
        ));
    }
    if effects.specular.is_some() {
        lines.push("          + specular highlight (no estimates)".to_string());
    }
    if effects.fog.is_some() {
        lines.push("          + fog over hit distance (no estimates)".to_string());
    }
    if effects.glow.is_some() {
        lines.push("          + glow from each ray's nearest approach (no estimates; its rays march without cones)".to_string());
    }
    if let Some(pt) = &effects.path_tracing {
        lines.push(format!(
            "          + path tracing per hit: up to {} bounces (Russian roulette from the third), each with a march and a normal, plus a ray to the {}° sun",
            pt.max_bounces, pt.sun_angle_degrees
        ));
    }
    if let Some(m) = &effects.motion_blur {
        lines.push(format!(
            "          + motion blur: each of the {} samples sees the timeline at its own time over {} of the frame interval",
            base.samples_per_pixel, m.shutter
        ));
    }
    let lens = base.camera.frame();
    if lens.has_lens() {
        lines.push(format!(
            "          + depth of field: thin lens of radius {}, focused at {:.4} (rays from the lens; needs samples_per_pixel of {} or more)",
            lens.aperture_radius, lens.focus_distance, crate::scene::LENS_SAMPLES
        ));
    }
    lines.push(match base.adapts() {
        Some(a) => format!(
            "          {}: {}x the per-sample work in every pixel, up to {}x where a pixel's error says so",
            base.sampling_summary(), a.first, base.samples_per_pixel
        ),
        _ => format!(
            "          {} sample(s) per pixel: {}x the per-sample work",
            base.samples_per_pixel, base.samples_per_pixel
        ),
    });
    lines
}
