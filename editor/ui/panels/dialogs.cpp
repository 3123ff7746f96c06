// Modal dialogs: open, save as (and replace?), unsaved changes, recovery, errors.

#include "ui/panels/panels.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"

#include <imgui_stdlib.h>

#include <algorithm>
#include <filesystem>

namespace stepwise::ui {

using editor::Editor;

void dialogs(UiState& ui, Editor& ed) {
    using editor::UiRequest;
    switch (ed.uiRequest) {
    case UiRequest::OpenDialog: ui.openDialogRequested = true; break;
    case UiRequest::SaveAsDialog: ui.saveAsDialogRequested = true; break;
    case UiRequest::Help: ui.showHelp = !ui.showHelp; break;
    case UiRequest::ConfirmDiscard: ImGui::OpenPopup("Unsaved changes"); break;
    case UiRequest::None: break;
    }
    if (ed.uiRequest != UiRequest::ConfirmDiscard) ed.uiRequest = UiRequest::None;
    else ed.uiRequest = UiRequest::None;  // the popup is open now; pending() remembers the action

    if (ui.openDialogRequested) {
        ImGui::OpenPopup("Open level");
        ui.openDialogRequested = false;
    }
    // Each dialog proposes afresh when it opens, from the level open now:
    // a path typed for another level (or for the other dialog) is not kept.
    if (ui.saveAsDialogRequested) {
        ImGui::OpenPopup("Save as");
        std::error_code cwd;
        ui.saveAsPath = editor::saveAsSuggestion(ed.doc.path, ui.levelsDir, std::filesystem::current_path(cwd)).string();
        ui.saveAsDialogRequested = false;
    }
    if (ui.saveStateRequested) {
        ImGui::OpenPopup("Save simulation state");
        std::error_code cwd;
        ui.saveAsPath = editor::saveStateSuggestion(ed.doc.path, ui.levelsDir, std::filesystem::current_path(cwd)).string();
        ui.saveStateRequested = false;
    }
    const ImVec2 center = ImGui::GetMainViewport()->GetCenter();
    ImGui::SetNextWindowPos(center, ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    if (ImGui::BeginPopupModal("Unsaved changes", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        ImGui::Text("%s has unsaved changes.", ed.doc.title().c_str());
        if (ImGui::Button("Save")) {
            ed.resolvePending(Editor::Resolution::Save);
            ImGui::CloseCurrentPopup();
        }
        ImGui::SameLine();
        if (ImGui::Button("Discard")) {
            ed.resolvePending(Editor::Resolution::Discard);
            ImGui::CloseCurrentPopup();
        }
        ImGui::SameLine();
        if (ImGui::Button("Cancel") || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape))) {
            ed.resolvePending(Editor::Resolution::Cancel);
            ImGui::CloseCurrentPopup();
        }
        ImGui::EndPopup();
    }
    ImGui::SetNextWindowPos(center, ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    ImGui::SetNextWindowSize(ImVec2(520 * ui.scale, 0), ImGuiCond_Appearing);
    if (ImGui::BeginPopupModal("Open level")) {
        const std::string folder = editor::dialogFolder(ed.doc.path, ui.levelsDir).string();
        ImGui::TextColored(kDim, "Levels in %s", folder.c_str());
        ImGui::BeginChild("levels", ImVec2(0, 200 * ui.scale), true);
        for (const std::string& f : editor::levelFiles(folder))
            if (ImGui::Selectable(f.c_str(), f == ui.openPath, ImGuiSelectableFlags_AllowDoubleClick)) {
                ui.openPath = f;
                if (ImGui::IsMouseDoubleClicked(0)) {
                    ImGui::CloseCurrentPopup();
                    ed.request(editor::PendingAction::Open, ui.openPath);
                }
            }
        ImGui::EndChild();
        // The path field takes the keyboard whenever nothing else in the
        // dialog is active (Ctrl+O, then type), and selects what it holds
        // when it takes it, so typing replaces a path chosen in the list
        // instead of appending to it.
        if (!ImGui::IsAnyItemActive()) ImGui::SetKeyboardFocusHere();
        ImGui::SetNextItemWidth(-1);
        const bool enter = ImGui::InputTextWithHint("##path", "path/to/level.json", &ui.openPath,
                                                    ImGuiInputTextFlags_EnterReturnsTrue | ImGuiInputTextFlags_AutoSelectAll);
        recordWidgetRect(ui, "open/path");
        const bool clicked = ImGui::Button("Open");
        recordWidgetRect(ui, "open/button");
        // Enter and the button take the same path: a failed open shows the
        // loader's message in the Error modal and the status line.
        if ((clicked || enter) && !ui.openPath.empty()) {
            ImGui::CloseCurrentPopup();
            ed.request(editor::PendingAction::Open, ui.openPath);
        }
        ImGui::SameLine();
        if (ImGui::Button("Cancel")) ImGui::CloseCurrentPopup();
        ImGui::EndPopup();
    }
    for (const char* name : {"Save as", "Save simulation state"}) {
        ImGui::SetNextWindowPos(center, ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
        ImGui::SetNextWindowSize(ImVec2(520 * ui.scale, 0), ImGuiCond_Appearing);
        if (ImGui::BeginPopupModal(name)) {
            // Type the path at once: the field takes the keyboard whenever
            // nothing else in the dialog is active (asked on the appearing
            // frame alone, the request is lost: an auto-sized window is
            // hidden on that frame).
            if (!ImGui::IsAnyItemActive()) ImGui::SetKeyboardFocusHere();
            ImGui::SetNextItemWidth(-1);
            const bool enter =
                ImGui::InputText("##saveas", &ui.saveAsPath, ImGuiInputTextFlags_EnterReturnsTrue);
            if ((ImGui::Button("Save") || enter) && !ui.saveAsPath.empty()) {
                ImGui::CloseCurrentPopup();
                if (editor::replacesAnotherFile(ui.saveAsPath, ed.doc.path)) {
                    // Another file is there: ask before writing over it.
                    ui.replaceConfirm = ui.saveAsPath;
                    ui.replaceIsState = std::string(name) != "Save as";
                } else if (std::string(name) == "Save as") {
                    ed.saveAs(ui.saveAsPath);
                } else {
                    ed.saveStateAs(ui.saveAsPath);
                }
            }
            ImGui::SameLine();
            if (ImGui::Button("Cancel")) ImGui::CloseCurrentPopup();
            ImGui::EndPopup();
        }
    }
    if (ui.replaceConfirm && !ImGui::IsPopupOpen("Replace file?")) ImGui::OpenPopup("Replace file?");
    ImGui::SetNextWindowPos(center, ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    if (ImGui::BeginPopupModal("Replace file?", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        ImGui::Text("%s already exists.", ui.replaceConfirm ? ui.replaceConfirm->c_str() : "");
        ImGui::Text("Replace it with %s?", ui.replaceIsState ? "the simulation state" : ed.doc.title().c_str());
        if (ImGui::Button("Replace")) {
            if (ui.replaceConfirm) {
                if (ui.replaceIsState) ed.saveStateAs(*ui.replaceConfirm);
                else ed.saveAs(*ui.replaceConfirm);
            }
            ui.replaceConfirm.reset();
            ImGui::CloseCurrentPopup();
        }
        ImGui::SameLine();
        if (ImGui::Button("Cancel") || ImGui::IsKeyPressed(ImGui::GetKeyIndex(ImGuiKey_Escape))) {
            ed.note("not saved: " + (ui.replaceConfirm ? *ui.replaceConfirm : std::string()) + " was kept");
            ui.replaceConfirm.reset();
            ImGui::CloseCurrentPopup();
        }
        ImGui::EndPopup();
    }
    if (ui.recoveryOffer) {
        ImGui::OpenPopup("Recover unsaved changes?");
    }
    ImGui::SetNextWindowPos(center, ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    if (ImGui::BeginPopupModal("Recover unsaved changes?", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        ImGui::Text("The editor stopped before %s was saved.", ed.doc.title().c_str());
        ImGui::TextColored(kDim, "Recovery copy: %s", ui.recoveryOffer ? ui.recoveryOffer->c_str() : "");
        if (ImGui::Button("Recover")) {
            if (ui.recoveryOffer) ed.recover(*ui.recoveryOffer);
            ui.recoveryOffer.reset();
            ImGui::CloseCurrentPopup();
        }
        ImGui::SameLine();
        if (ImGui::Button("Discard it")) {
            ed.discardRecovery();
            ui.recoveryOffer.reset();
            ImGui::CloseCurrentPopup();
        }
        ImGui::EndPopup();
    }
    // A bad file (or any refused operation) gets the loader's message.
    if (!ed.errorModal.empty() && !ImGui::IsPopupOpen("Error")) {
        ImGui::OpenPopup("Error");
        // Enter dismisses the modal only once it has been let go of since
        // the modal opened: the Enter that confirmed a path in the Open
        // dialog (and opened this modal in the same frame) must not also
        // close it before it is seen.
        ui.errorEnterArmed = false;
    }
    const int enterKey = ImGui::GetKeyIndex(ImGuiKey_Enter);
    if (!ImGui::IsKeyDown(enterKey)) ui.errorEnterArmed = true;
    ImGui::SetNextWindowPos(center, ImGuiCond_Appearing, ImVec2(0.5f, 0.5f));
    ImGui::SetNextWindowSizeConstraints(ImVec2(360 * ui.scale, 0), ImVec2(900 * ui.scale, 600 * ui.scale));
    if (ImGui::BeginPopupModal("Error", nullptr, ImGuiWindowFlags_AlwaysAutoResize)) {
        ImGui::PushTextWrapPos(ImGui::GetCursorPosX() + 640 * ui.scale);
        ImGui::TextColored(kRed, "%s", displayableText(ed.errorModal).c_str());
        ImGui::PopTextWrapPos();
        if (ImGui::Button("OK") || (ui.errorEnterArmed && ImGui::IsKeyPressed(enterKey, false))) {
            ed.errorModal.clear();
            ImGui::CloseCurrentPopup();
        }
        ImGui::EndPopup();
    }
}

} // namespace stepwise::ui
