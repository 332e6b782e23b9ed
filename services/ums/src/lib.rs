//! UMS: the spatial uncertainty map.
