"""Built-in URDF templates (xacro), shipped as package data ``urdfkit.templates``."""
