//! Camera: renders the simulated world into shared-memory frames.
