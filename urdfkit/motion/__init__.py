"""urdfkit.motion: see docs/architecture.md. Imports nothing."""
