//! Encoders: DRV shaft-encoder reports to odometry with the commanded motion.
