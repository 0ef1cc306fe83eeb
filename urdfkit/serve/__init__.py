"""Front ends for editors and agents: a Language Server (``lsp``) and an MCP server (``mcp``)."""
