// The editor's file dialog: per-action settings, path resolution and the ImGui window.
#include "file_dialog.hpp"
#include "smpl/text.hpp"

#include <imgui.h>

#include <algorithm>
#include <cctype>
#include <cstring>
#include <stdexcept>
#include <system_error>

namespace caliper::editor {

namespace fs = std::filesystem;

namespace {

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (size_t i = 0; i < v.size(); ++i) {
    if (i > 0) s += i + 1 == v.size() ? " or " : ", ";
    s += v[i];
  }
  return s;
}

void copy_text(char* out, size_t size, const std::string& text) {
  std::snprintf(out, size, "%s", text.c_str());
}

}  // namespace

FileActionInfo file_action_info(FileAction action,
                                const std::vector<std::string>& export_extensions) {
  switch (action) {
    case FileAction::OpenProfile:
      return {"Open a measurement profile", "Open", false, {".json"}, ""};
    case FileAction::OpenSession:
      return {"Open a VR measuring session", "Open", false, {".json", ".jsonl"}, ""};
    case FileAction::OpenModel:
      return {"Open a body model", "Open", false, {".npz", ".pkl"}, ""};
    case FileAction::SaveProfile:
      return {"Save the measurement profile", "Save", true, {".json"}, "profile"};
    case FileAction::Export:
      return {"Export the avatar", "Export", true, export_extensions, "avatar"};
    case FileAction::Screenshot:
      return {"Save a screenshot", "Save", true, {".png"}, "screenshot"};
  }
  throw std::invalid_argument("unknown file action");
}

fs::path resolve_dialog_path(const fs::path& dir, const std::string& name,
                             const FileActionInfo& info, const std::string& chosen_extension) {
  const auto first = name.find_first_not_of(" \t");
  if (first == std::string::npos) throw std::invalid_argument("type a file name first");
  const std::string trimmed = name.substr(first, name.find_last_not_of(" \t") - first + 1);
  fs::path p = fs::path(trimmed).is_absolute() ? fs::path(trimmed) : dir / trimmed;
  if (!p.has_filename() || trimmed.back() == '/')
    throw std::invalid_argument("'" + trimmed + "' is a folder: type a file name");
  const std::string ext = smpl::to_lower(p.extension().string());
  const bool known =
      std::find(info.extensions.begin(), info.extensions.end(), ext) != info.extensions.end();
  if (known) return p.lexically_normal();
  if (info.save && ext.empty()) {
    p += chosen_extension.empty() ? info.extensions.front() : chosen_extension;
    return p.lexically_normal();
  }
  if (ext.empty()) return p.lexically_normal();  // opening: a file without extension is tried
  throw std::invalid_argument("'" + p.filename().string() + "': " + info.title + " uses " +
                              join(info.extensions) + " files, not " + ext);
}

void FileDialog::open(FileAction action, const FileActionInfo& info, const fs::path& folder) {
  action_ = action;
  info_ = info;
  std::error_code ec;
  folder_ = folder.empty() ? fs::current_path(ec) : folder;
  if (!fs::is_directory(folder_, ec)) folder_ = fs::current_path(ec);
  copy_text(name_, sizeof name_, info.save ? info.default_name + info.extensions.front() : "");
  extension_ = 0;
  error_.clear();
  confirm_overwrite_.reset();
  open_ = just_opened_ = true;
  list_folder();
}

void FileDialog::list_folder() {
  folders_.clear();
  files_.clear();
  copy_text(folder_text_, sizeof folder_text_, folder_.string());
  std::error_code ec;
  for (fs::directory_iterator it(folder_, fs::directory_options::skip_permission_denied, ec), end;
       !ec && it != end; it.increment(ec)) {
    const std::string n = it->path().filename().string();
    if (n.empty() || n[0] == '.') continue;
    std::error_code e2;
    if (it->is_directory(e2)) {
      folders_.push_back(n);
    } else {
      const std::string ext = smpl::to_lower(it->path().extension().string());
      if (std::find(info_.extensions.begin(), info_.extensions.end(), ext) !=
          info_.extensions.end())
        files_.push_back(n);
    }
  }
  if (ec) error_ = "cannot list " + folder_.string() + ": " + ec.message();
  std::sort(folders_.begin(), folders_.end());
  std::sort(files_.begin(), files_.end());
}

std::optional<fs::path> FileDialog::accept(const std::string& name) {
  try {
    const std::string ext = info_.extensions.at(static_cast<size_t>(extension_));
    const fs::path p = resolve_dialog_path(folder_, name, info_, ext);
    std::error_code ec;
    if (!info_.save) {
      if (!fs::is_regular_file(p, ec)) {
        error_ = p.string() + " does not exist (or is not a file)";
        return std::nullopt;
      }
    } else {
      if (fs::is_directory(p, ec)) {
        error_ = p.string() + " is a folder: type a file name";
        return std::nullopt;
      }
      if (fs::exists(p, ec) && !confirm_overwrite_) {
        confirm_overwrite_ = p;
        return std::nullopt;
      }
      if (p.has_parent_path()) {
        fs::create_directories(p.parent_path(), ec);
        if (ec) {
          error_ = "cannot create the folder " + p.parent_path().string() + ": " + ec.message();
          return std::nullopt;
        }
      }
    }
    folder_ = p.parent_path();
    confirm_overwrite_.reset();
    open_ = false;
    return p;
  } catch (const std::exception& e) {
    error_ = e.what();
    return std::nullopt;
  }
}

std::optional<fs::path> FileDialog::draw(UiProbe& probe) {
  if (!open_) return std::nullopt;
  const std::string id = info_.title + "###file_dialog";
  if (just_opened_) {
    ImGui::OpenPopup(id.c_str());
    just_opened_ = false;
  }
  const ImGuiIO& io = ImGui::GetIO();
  ImGui::SetNextWindowSize(
      ImVec2(std::min(720.0f, io.DisplaySize.x - 40), std::min(520.0f, io.DisplaySize.y - 40)),
      ImGuiCond_Appearing);
  ImGui::SetNextWindowPos(ImVec2(io.DisplaySize.x / 2, io.DisplaySize.y / 2), ImGuiCond_Appearing,
                          ImVec2(0.5f, 0.5f));
  if (!ImGui::BeginPopupModal(id.c_str(), nullptr, ImGuiWindowFlags_NoSavedSettings)) {
    open_ = false;  // closed by ImGui (e.g. the popup stack was cleared)
    return std::nullopt;
  }
  std::optional<fs::path> chosen =
      confirm_overwrite_ ? draw_overwrite_question(probe) : draw_browser(probe);
  if (!open_) ImGui::CloseCurrentPopup();
  ImGui::EndPopup();
  return chosen;
}

std::optional<fs::path> FileDialog::draw_overwrite_question(UiProbe& probe) {
  std::optional<fs::path> chosen;
  ImGui::TextWrapped("%s already exists. Replace it?", confirm_overwrite_->string().c_str());
  const bool replace = ImGui::Button("Replace");
  probe.track("Replace");
  if (replace) chosen = accept(name_);
  ImGui::SameLine();
  const bool keep = ImGui::Button("Keep the file");
  probe.track("Keep the file");
  if (keep || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape))) confirm_overwrite_.reset();
  return chosen;
}

std::optional<fs::path> FileDialog::draw_browser(UiProbe& probe) {
  draw_folder_bar(probe);
  std::optional<fs::path> chosen = draw_entries(probe);
  const bool typed_enter = draw_name_and_type(probe);
  ImGui::TextDisabled("%s files; a name without a folder goes to the folder above",
                      join(info_.extensions).c_str());
  if (!error_.empty()) ImGui::TextColored(ImVec4(0.8f, 0.1f, 0.1f, 1), "%s", error_.c_str());
  const bool ok = ImGui::Button(info_.button.c_str());
  probe.track(info_.button.c_str());
  if (ok || typed_enter) {
    error_.clear();
    chosen = accept(name_);
  }
  ImGui::SameLine();
  const bool cancel = ImGui::Button("Cancel");
  probe.track("Cancel");
  if (cancel ||
      (!ImGui::GetIO().WantTextInput && ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape))))
    open_ = false;
  return chosen;
}

void FileDialog::draw_folder_bar(UiProbe& probe) {
  if (ImGui::Button("Up")) {
    if (folder_.has_parent_path() && folder_.parent_path() != folder_) {
      folder_ = folder_.parent_path();
      list_folder();
    }
  }
  probe.track("Up");
  ImGui::SameLine();
  ImGui::SetNextItemWidth(-1);
  if (ImGui::InputText("##folder", folder_text_, sizeof folder_text_,
                       ImGuiInputTextFlags_EnterReturnsTrue)) {
    std::error_code ec;
    if (fs::is_directory(folder_text_, ec)) {
      folder_ = folder_text_;
      error_.clear();
      list_folder();
    } else {
      error_ = std::string(folder_text_) + " is not a folder";
    }
  }
  probe.track("##folder");
}

std::optional<fs::path> FileDialog::draw_entries(UiProbe& probe) {
  std::optional<fs::path> chosen;
  const float footer = ImGui::GetFrameHeightWithSpacing() * 3 + ImGui::GetTextLineHeight() * 2;
  ImGui::BeginChild("##entries", ImVec2(0, -footer), true);
  std::optional<std::string> enter;
  for (const std::string& f : folders_) {
    const std::string label = "[folder] " + f;
    if (ImGui::Selectable(label.c_str(), false, ImGuiSelectableFlags_AllowDoubleClick) &&
        ImGui::IsMouseDoubleClicked(ImGuiMouseButton_Left))
      enter = f;
    probe.track(label.c_str());
  }
  for (const std::string& f : files_) {
    const bool selected = f == name_;
    if (ImGui::Selectable(f.c_str(), selected, ImGuiSelectableFlags_AllowDoubleClick)) {
      copy_text(name_, sizeof name_, f);
      if (ImGui::IsMouseDoubleClicked(ImGuiMouseButton_Left)) chosen = accept(name_);
    }
    probe.track(f.c_str());
  }
  if (folders_.empty() && files_.empty())
    ImGui::TextDisabled("no folders or %s files here", join(info_.extensions).c_str());
  ImGui::EndChild();
  if (enter) {
    folder_ /= *enter;
    list_folder();
  }
  return chosen;
}

bool FileDialog::draw_name_and_type(UiProbe& probe) {
  const bool choose_type = info_.extensions.size() > 1 && info_.save;
  ImGui::SetNextItemWidth(choose_type ? -130.0f : -1.0f);
  if (ImGui::IsWindowAppearing()) ImGui::SetKeyboardFocusHere();
  const bool typed_enter =
      ImGui::InputText("##name", name_, sizeof name_, ImGuiInputTextFlags_EnterReturnsTrue);
  probe.track("##name");
  if (!choose_type) return typed_enter;
  ImGui::SameLine();
  ImGui::SetNextItemWidth(-1);
  const std::string current = info_.extensions[static_cast<size_t>(extension_)];
  if (ImGui::BeginCombo("##type", current.c_str())) {
    for (size_t i = 0; i < info_.extensions.size(); ++i) {
      if (ImGui::Selectable(info_.extensions[i].c_str(), static_cast<int>(i) == extension_)) {
        extension_ = static_cast<int>(i);
        // The name follows the chosen type.
        fs::path n(name_);
        if (!n.extension().empty()) {
          n.replace_extension(info_.extensions[i]);
          copy_text(name_, sizeof name_, n.string());
        }
      }
    }
    ImGui::EndCombo();
  }
  probe.track("##type");
  return typed_enter;
}

}  // namespace caliper::editor
