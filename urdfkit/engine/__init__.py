"""urdfkit.engine: see docs/architecture.md. Imports nothing."""
