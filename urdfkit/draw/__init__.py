"""urdfkit.draw: see docs/architecture.md. Imports nothing."""
