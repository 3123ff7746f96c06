#pragma once
/// \file panels.hpp
/// Internal to editor/ui: the panels drawEditorUi (editor_ui.cpp) builds,
/// one file each in editor/ui/panels/, and the colours they share.

#include "ui/editor_ui.hpp"

namespace stepwise::ui {

inline const ImVec4 kAccent{0.35f, 0.62f, 0.95f, 1.0f};
inline const ImVec4 kGold{1.0f, 0.82f, 0.40f, 1.0f};
inline const ImVec4 kRed{0.95f, 0.42f, 0.38f, 1.0f};
inline const ImVec4 kGreen{0.45f, 0.85f, 0.55f, 1.0f};
inline const ImVec4 kDim{0.60f, 0.63f, 0.68f, 1.0f};

void menuBar(UiState& ui, editor::Editor& ed);                             // menu_bar.cpp
void toolsPanel(UiState& ui, editor::Editor& ed, const PanelRects& r);     // tools_panel.cpp
void entitiesPanel(UiState& ui, editor::Editor& ed, const PanelRects& r);  // entities_panel.cpp
void viewportPanel(UiState& ui, editor::Editor& ed, const PanelRects& r);  // viewport_panel.cpp
void worldPanel(UiState& ui, editor::Editor& ed, const PanelRects& r);     // world_panel.cpp
void debugPanel(UiState& ui, editor::Editor& ed, const PanelRects& r);     // debug_panel.cpp
void statusBar(UiState& ui, editor::Editor& ed);                           // status_help.cpp
void helpWindow(UiState& ui);                                              // status_help.cpp
void dialogs(UiState& ui, editor::Editor& ed);                             // dialogs.cpp

} // namespace stepwise::ui
