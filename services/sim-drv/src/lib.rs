//! Simulated Denning DRV on a pseudo-terminal.
