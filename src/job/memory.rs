//! Whether a frame fits in memory: what this process can still have, from
//! /proc and the control group's limits, against what a frame's buffers need.

use crate::error::Error;
use crate::job::plan::Plan;
use crate::output::Format;

impl Plan {
    /// Refuses a size whose frame would need more memory than this machine
    /// (or this process's address-space limit) has to give, before anything
    /// is written: a frame too large would otherwise fail part-way, or be
    /// killed with the machine short of memory.
    pub fn check_memory(&self, size_given: bool) -> anyhow::Result<()> {
        // No track animates the sample count: the base scene has it.
        let base = &self.timeline.base;
        let sums = match (self.preview || base.samples_per_pixel <= 1, &base.adaptive) {
            (true, _) => crate::render::Sums::None,
            (false, None) => crate::render::Sums::Uniform,
            (false, Some(_)) => crate::render::Sums::Adaptive,
        };
        let exr = self.formats.contains(&Format::Exr);
        let size = [self.width, self.height];
        // No track changes the projection: the base scene's is every frame's.
        let partial = !base.camera.frame().covers_all();
        let need = crate::render::frame_bytes(size, self.layers(), exr, sums, partial);
        let Some((have, whose)) = memory_available() else {
            return Ok(());
        };
        if need <= have {
            return Ok(());
        }
        let gib = |bytes: u64| bytes as f64 / (1u64 << 30) as f64;
        let message = format!(
            "{} needs about {:.1} GiB for a frame's buffers, and {whose} {:.1} GiB \
             to give: render it smaller, or with more memory",
            self.size_told(size_given),
            gib(need),
            gib(have)
        );
        // The timeline's own size is the timeline's fault (exit 3), at its line.
        Err(match size_given {
            true => Error::usage("--size", message),
            false => self.timeline.field_error("size", message),
        }
        .into())
    }

    /// The size measured, as the user knows it: a size --preview halved
    /// is not the one they wrote, so the message says both.
    fn size_told(&self, size_given: bool) -> String {
        let (w, h) = (self.width, self.height);
        match (self.preview, size_given) {
            (false, _) => format!("{w}x{h}"),
            (true, true) => format!("halved by --preview to {w}x{h},"),
            (true, false) => {
                let (file_w, file_h) = (self.timeline.width, self.timeline.height);
                format!("{file_w}x{file_h}, halved by --preview to {w}x{h},")
            }
        }
    }
}

/// Memory this process can still have, where Linux tells, and whose limit
/// that is: the least of what the machine has available (memory and swap,
/// /proc/meminfo), what its control group may still use (cgroup v2's
/// memory.max, or v1's limit, less what it uses: a container's limit),
/// and the process's address-space limit (`ulimit -v`, /proc/self/limits,
/// less what it has mapped).
pub fn memory_available() -> Option<(u64, &'static str)> {
    let read = |path: &str| std::fs::read_to_string(path).ok();
    let number = |text: Option<String>| text?.trim().parse::<u64>().ok();
    // "Key:  <n> kB" lines of /proc/meminfo and /proc/self/status, in bytes.
    let field = |text: &str, key: &str| -> Option<u64> {
        let line = text.lines().find(|l| l.starts_with(key))?;
        Some(line.split_whitespace().nth(1)?.parse::<u64>().ok()? * 1024)
    };
    let meminfo = read("/proc/meminfo")?;
    let machine = field(&meminfo, "MemAvailable:")? + field(&meminfo, "SwapFree:").unwrap_or(0);
    let mut limits = vec![(machine, "this machine has")];
    // A limit of "max" (v2) parses as none; v1's unlimited is a huge number.
    let group = number(read("/sys/fs/cgroup/memory.max"))
        .zip(number(read("/sys/fs/cgroup/memory.current")))
        .or_else(|| {
            number(read("/sys/fs/cgroup/memory/memory.limit_in_bytes"))
                .zip(number(read("/sys/fs/cgroup/memory/memory.usage_in_bytes")))
        });
    if let Some((max, used)) = group {
        limits.push((max.saturating_sub(used), "this control group has"));
    }
    // "Max address space  <soft> <hard> bytes": "unlimited" parses as none.
    let address_space = read("/proc/self/limits").and_then(|text| {
        let line = text.lines().find(|l| l.starts_with("Max address space"))?;
        line.split_whitespace().nth(3)?.parse::<u64>().ok()
    });
    if let Some(limit) = address_space {
        let mapped = read("/proc/self/status")
            .and_then(|s| field(&s, "VmSize:"))
            .unwrap_or(0);
        limits.push((limit.saturating_sub(mapped), "this process may map"));
    }
    limits.into_iter().min_by_key(|(bytes, _)| *bytes)
}
