"""urdfkit.sources: see docs/architecture.md. Imports nothing."""
