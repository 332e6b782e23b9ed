//! Denning bridge: the DRV serial protocol between a serial line and the bus.
