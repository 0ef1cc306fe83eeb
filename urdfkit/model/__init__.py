"""urdfkit.model: see docs/architecture.md. Imports nothing."""
