"""urdfkit.checks: see docs/architecture.md. Imports nothing."""
