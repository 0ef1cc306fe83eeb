"""urdfkit.core: see docs/architecture.md. Imports nothing."""
