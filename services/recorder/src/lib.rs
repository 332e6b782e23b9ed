//! Recorder: every topic to an MCAP file with the ROS 2 conventions.
