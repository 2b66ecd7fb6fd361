/// \file commands.hpp
/// The editor's text command language (headless scripts and tests, docs/editor.md): one line,
/// one command, e.g. "set height 180 cm", "units imperial", "level 2", "undo". Blank lines and
/// lines starting with '#' do nothing.
#pragma once

#include <string>
#include <vector>

namespace caliper::app {

class EditorCore;

/// Runs one command line on `core`. Returns false, posting the error "command '<line>': <what
/// was expected>", for an unknown or malformed command; otherwise what the command returns
/// (the core posts its own errors). View-only commands that need a renderer (screenshot) are
/// not handled here: the caller handles them first.
bool run_command(EditorCore& core, const std::string& line);

/// The command names run_command() knows, sorted.
std::vector<std::string> command_names();

}  // namespace caliper::app
