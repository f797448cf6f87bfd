//! Per-frame counters: samples, hits and the estimates each stage spent.

/// Work counted while rendering one frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct FrameStats {
    /// Orbits computed for distance estimates and membership tests, every
    /// stage together (1 per analytic estimate, 5 per gradient estimate).
    pub de_evaluations: u64,
    /// The same by stage: primary marching, normals, shadow marches, occlusion.
    pub primary_evaluations: u64,
    pub normal_evaluations: u64,
    pub shadow_evaluations: u64,
    pub occlusion_evaluations: u64,
    /// Path tracing: bounce rays (marching and normals) and rays towards the sun.
    pub bounce_evaluations: u64,
    pub sun_evaluations: u64,
    pub samples: u64,
    pub hits: u64,
    /// The most evaluations any one pixel took.
    pub max_pixel_evaluations: u64,
    /// Orbit iterations over every stage: the kernel's unit of work.
    #[serde(default)]
    pub de_iterations: u64,
    /// Samples whose colour came out NaN or infinite and were replaced by
    /// black. Every known cause is guarded upstream, so this should stay 0;
    /// debug builds stop at the first one instead.
    pub repaired_samples: u64,
    /// Camera rays that ran out of `quality.max_steps` (counted as hits,
    /// where they stopped): many mean too few steps for the scene, or a
    /// small fudge.
    #[serde(default)]
    pub out_of_steps: u64,
}

impl FrameStats {
    /// Evaluations over every stage.
    pub fn stage_total(&self) -> u64 {
        self.primary_evaluations
            + self.normal_evaluations
            + self.shadow_evaluations
            + self.occlusion_evaluations
            + self.bounce_evaluations
            + self.sun_evaluations
    }

    /// These counts as a finished frame (or band) reports them: the stage
    /// total and the most any one pixel took.
    pub(super) fn finished(self, max_pixel_evaluations: u64) -> FrameStats {
        FrameStats {
            de_evaluations: self.stage_total(),
            max_pixel_evaluations,
            ..self
        }
    }
}

impl std::ops::Add for FrameStats {
    type Output = FrameStats;
    fn add(self, o: FrameStats) -> FrameStats {
        FrameStats {
            de_evaluations: self.de_evaluations + o.de_evaluations,
            primary_evaluations: self.primary_evaluations + o.primary_evaluations,
            normal_evaluations: self.normal_evaluations + o.normal_evaluations,
            shadow_evaluations: self.shadow_evaluations + o.shadow_evaluations,
            occlusion_evaluations: self.occlusion_evaluations + o.occlusion_evaluations,
            bounce_evaluations: self.bounce_evaluations + o.bounce_evaluations,
            sun_evaluations: self.sun_evaluations + o.sun_evaluations,
            samples: self.samples + o.samples,
            hits: self.hits + o.hits,
            max_pixel_evaluations: self.max_pixel_evaluations.max(o.max_pixel_evaluations),
            de_iterations: self.de_iterations + o.de_iterations,
            repaired_samples: self.repaired_samples + o.repaired_samples,
            out_of_steps: self.out_of_steps + o.out_of_steps,
        }
    }
}
