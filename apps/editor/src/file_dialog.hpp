/// \file file_dialog.hpp
/// The editor's file dialog: one per action (open a profile, session or model; save a profile;
/// export; screenshot), each with its own title, file types and default name; a folder
/// browser, a name field, overwrite confirmation, and missing folders created on save. Drawn
/// with Dear ImGui as a modal window; the path logic (resolve_dialog_path) is plain C++.
#pragma once

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "ui_probe.hpp"

namespace caliper::editor {

enum class FileAction { OpenProfile, OpenSession, OpenModel, SaveProfile, Export, Screenshot };

/// What a dialog of one action asks for.
struct FileActionInfo {
  std::string title;                    ///< e.g. "Export the avatar"
  std::string button;                   ///< "Open", "Save", "Export"
  bool save = false;                    ///< writes a file (overwrite question, folders made)
  std::vector<std::string> extensions;  ///< accepted, lower case with the dot; [0] the default
  std::string default_name;             ///< stem without extension, e.g. "avatar"
};

/// The dialog settings of `action`; `export_extensions` lists the export formats (the core's).
FileActionInfo file_action_info(FileAction action,
                                const std::vector<std::string>& export_extensions);

/// The path a dialog returns for `name` typed in folder `dir`: absolute names are kept,
/// relative ones (which may contain folders) are taken inside `dir`. Saving: a name without
/// an accepted extension gets `chosen_extension`. Throws std::invalid_argument with a
/// sentence for the user when the name is empty or has an extension the action cannot use.
std::filesystem::path resolve_dialog_path(const std::filesystem::path& dir, const std::string& name,
                                          const FileActionInfo& info,
                                          const std::string& chosen_extension);

/// The ImGui dialog. Open it with open(); draw() every frame; draw() returns the chosen path
/// once, when the user accepts (after an overwrite question when the file exists; for saving,
/// the missing folders of the path are created first).
class FileDialog {
 public:
  void open(FileAction action, const FileActionInfo& info, const std::filesystem::path& folder);
  bool is_open() const { return open_; }
  void close() { open_ = false; }
  FileAction action() const { return action_; }
  std::optional<std::filesystem::path> draw(UiProbe& probe);
  /// The last folder a file was chosen in (start folder of the next dialog).
  const std::filesystem::path& folder() const { return folder_; }

 private:
  void list_folder();
  std::optional<std::filesystem::path> accept(const std::string& name);
  /// The "already exists. Replace it?" question; returns the path when Replace is pressed.
  std::optional<std::filesystem::path> draw_overwrite_question(UiProbe& probe);
  /// Folder bar, entries, name, type and buttons; returns the path once the user accepts one.
  std::optional<std::filesystem::path> draw_browser(UiProbe& probe);
  /// Up and the editable folder path (Enter goes to a typed folder, else an error is shown).
  void draw_folder_bar(UiProbe& probe);
  /// The folders (double click enters one) and matching files (click names it, double click
  /// accepts it) of the current folder; returns the path of an accepted file.
  std::optional<std::filesystem::path> draw_entries(UiProbe& probe);
  /// The name field and, when saving with several types, the type list (the name's extension
  /// follows it); returns true when Enter was pressed in the name field.
  bool draw_name_and_type(UiProbe& probe);

  bool open_ = false, just_opened_ = false;
  FileAction action_ = FileAction::OpenProfile;
  FileActionInfo info_;
  std::filesystem::path folder_;
  std::vector<std::string> folders_, files_;
  char name_[512] = "";
  char folder_text_[1024] = "";
  int extension_ = 0;
  std::string error_;
  std::optional<std::filesystem::path> confirm_overwrite_;
};

}  // namespace caliper::editor
