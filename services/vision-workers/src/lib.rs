//! Vision workers: perceptual algorithms on camera frames read in place.
