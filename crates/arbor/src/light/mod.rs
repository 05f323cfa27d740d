//! Lights: point, area and directional lights for shading; the environment map for rays that miss.

pub mod environment;
