-- Neovim (0.7+), headless, as a user's editor: urdfkit lsp attached to a file, its diagnostics
-- written out, a code action applied and the buffer saved. Driven by tests/test_editor_nvim.py.
--   URDFKIT_PYTHON  the Python that runs `-m urdfkit lsp`
--   URDFKIT_FILE    the file to open
--   URDFKIT_OUT     where to write "code line" per diagnostic, then "applied TITLE"
--   URDFKIT_ACTION  the start of the title of the code action to apply
--   URDFKIT_WANT    how many diagnostics to wait for
local file = os.getenv("URDFKIT_FILE")
local out = io.open(os.getenv("URDFKIT_OUT"), "w")
local want = tonumber(os.getenv("URDFKIT_WANT") or "1")
vim.cmd("edit " .. vim.fn.fnameescape(file))
local bufnr = vim.api.nvim_get_current_buf()
local client_id = vim.lsp.start_client({
  name = "urdfkit",
  cmd = { os.getenv("URDFKIT_PYTHON"), "-m", "urdfkit", "lsp" },
  root_dir = vim.fn.fnamemodify(file, ":p:h"),
})
vim.lsp.buf_attach_client(bufnr, client_id)
local function lsp_diagnostics()
  local found = {}
  for _, d in ipairs(vim.diagnostic.get(bufnr)) do
    local raw = d.user_data and d.user_data.lsp or {}
    table.insert(found, {
      code = raw.code or d.code, message = d.message, severity = d.severity,
      source = d.source,
      range = { start = { line = d.lnum, character = d.col },
                ["end"] = { line = d.end_lnum or d.lnum, character = d.end_col or d.col } } })
  end
  return found
end
vim.wait(90000, function() return #vim.diagnostic.get(bufnr) >= want end, 50)
for _, d in ipairs(vim.diagnostic.get(bufnr)) do
  local raw = d.user_data and d.user_data.lsp or {}
  out:write(string.format("%s %d\n", tostring(raw.code or d.code), d.lnum))
end
local params = {
  textDocument = { uri = vim.uri_from_bufnr(bufnr) },
  range = { start = { line = 0, character = 0 },
            ["end"] = { line = vim.api.nvim_buf_line_count(bufnr), character = 0 } },
  context = { diagnostics = lsp_diagnostics() },
}
local answers = vim.lsp.buf_request_sync(bufnr, "textDocument/codeAction", params, 60000) or {}
local wanted = os.getenv("URDFKIT_ACTION") or ""
for _, answer in pairs(answers) do
  for _, action in ipairs(answer.result or {}) do
    if wanted ~= "" and action.title:sub(1, #wanted) == wanted then
      vim.lsp.util.apply_workspace_edit(action.edit, "utf-16")
      vim.cmd("write")
      out:write("applied " .. action.title .. "\n")
      wanted = ""
    end
  end
end
out:close()
vim.lsp.stop_client(client_id)
vim.cmd("qall!")
