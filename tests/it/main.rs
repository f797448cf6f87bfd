//! Integration tests: the real `mandelreel` binary on tiny frames in temporary folders.

mod util;

mod accuracy;
mod auto;
mod bench;
mod browser;
mod cli;
mod compositing;
mod deep;
mod deep_oracle;
mod explore_api;
mod farm;
mod formats;
mod fuzz;
mod gallery;
mod layers;
mod limits;
mod locations;
mod names;
mod palette;
mod projections;
mod quality;
mod quaternion;
mod recipes;
mod resume;
mod sampling;
mod stability;
mod surface;
mod validation;
mod video;
mod write_errors;
