// The functions a .wasm here imports from its host (the page's app.js, or run-node.mjs), declared
// to emscripten's linker so that it leaves them as imports.
mergeInto(LibraryManager.library, {
  // Writes the NUL-terminated text at the given address (examples/firmware/main.cpp, STATSIM_WEB).
  statsim_write: function() {},
});
