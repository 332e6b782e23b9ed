//! Sonar: raw DRV bank readings to the 24-sensor ring, with the panic-stop reflex.
