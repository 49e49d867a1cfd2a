"""The project's MAVLink dialect: companion.xml and the module mavgen generates from it."""
