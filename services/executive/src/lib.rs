//! Executive: runs a mission by commanding motions and monitoring progress.
