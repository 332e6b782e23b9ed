//! Units: everything on the bus is SI; the papers and the DRV speak feet, inches and degrees.

/// One foot in metres.
pub const FT: f64 = 0.3048;
/// One inch in metres.
pub const INCH: f64 = 0.0254;
