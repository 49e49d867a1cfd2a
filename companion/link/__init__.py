"""Vehicle-side MAVLink: endpoints, the codec, and one state machine per microservice."""
