//! How the command line names and describes the values of the library's
//! choices (`--format`, `--aov`, `--exr-compression`): clap's side of them
//! lives here, so the library's types carry no argument parser.

use crate::output::exr::ExrCompression;
use crate::output::{Aov, Format};
use clap::builder::PossibleValue;
use clap::ValueEnum;

impl ValueEnum for Format {
    fn value_variants<'a>() -> &'a [Self] {
        &Format::ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        let help = match self {
            Format::Png => "8-bit sRGB PNG, dithered (no banding in smooth gradients)",
            Format::Png16 => "16-bit sRGB PNG",
            Format::Png16Alpha => "16-bit sRGB PNG with straight (unpremultiplied) alpha",
            Format::Exr => {
                "OpenEXR: linear half-float premultiplied R, G, B, A and a float depth.Z \
                 (camera distance), plus the layers --aov asks for"
            }
        };
        Some(PossibleValue::new(self.name()).help(help))
    }
}

impl ValueEnum for Aov {
    fn value_variants<'a>() -> &'a [Self] {
        &Aov::ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        let help = match self {
            Aov::Normal => "Surface normal: N.X, N.Y, N.Z",
            Aov::Albedo => "Orbit-trap albedo: albedo.R, albedo.G, albedo.B",
            Aov::Traps => "Orbit traps: trap.origin (smallest |z|²), trap.x, trap.y, trap.z",
            Aov::Steps => "Distance estimates spent per pixel: DE (a cost heat map)",
        };
        Some(PossibleValue::new(self.name()).help(help))
    }
}

impl ValueEnum for ExrCompression {
    fn value_variants<'a>() -> &'a [Self] {
        &ExrCompression::ALL
    }

    fn to_possible_value(&self) -> Option<PossibleValue> {
        Some(PossibleValue::new(self.name()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_value_is_parsed_back_by_its_name_in_any_case() {
        for f in Format::ALL {
            assert_eq!(Format::from_str(f.name(), true), Ok(f));
            assert_eq!(Format::from_str(&f.name().to_uppercase(), true), Ok(f));
        }
        for a in Aov::ALL {
            assert_eq!(Aov::from_str(a.name(), false), Ok(a));
        }
        for c in ExrCompression::ALL {
            assert_eq!(ExrCompression::from_str(c.name(), false), Ok(c));
        }
        assert!(Format::from_str("jpeg", true).is_err());
    }
}
