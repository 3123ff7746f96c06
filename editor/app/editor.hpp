#pragma once
/// \file editor.hpp
/// The editor model, with no window: document, undo stack, selection,
/// tools, simulation controller, camera and clipboard. The ImGui panels
/// (editor/ui) and the scripted mode drive it through these calls and
/// through InputEvents, and the unit tests drive it the same way.

#include "app/command_stack.hpp"
#include "app/document.hpp"
#include "app/events.hpp"
#include "app/simulation.hpp"
#include "app/tools/tools.hpp"
#include "app/view_camera.hpp"

#include "frame_input.hpp"

#include "stepwise/component_table.hpp"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace stepwise::editor {

/// Actions the model cannot finish alone: they need a dialog.
enum class UiRequest : std::uint8_t { None, OpenDialog, SaveAsDialog, ConfirmDiscard, Help };

/// What waits behind an unsaved-changes question.
enum class PendingAction : std::uint8_t { None, New, Open, Quit };

class Editor {
public:
    Editor();

    // ---- document -------------------------------------------------------
    Document doc;
    CommandStack commands;
    Simulation sim;
    ViewCamera view;
    std::vector<Entity> selection;
    Tool tool = Tool::Select;
    bool snap = false;
    double snapSpacing = 0.25;   ///< metres
    render::OverlaySet overlays;
    render::TrailRecorder trails{64};

    /// Opens a level; on failure sets errorModal to the loader's message and
    /// keeps the current document. Respects nothing: ask first (requestOpen).
    bool open(const std::filesystem::path& file);
    /// Replaces the document with a new level.
    void newDocument();
    /// Saves to the document's path; with none, asks for one (SaveAsDialog).
    bool save();
    bool saveAs(const std::filesystem::path& file);
    /// Saves the current simulation state (not the edited level) to `file`.
    bool saveStateAs(const std::filesystem::path& file);
    /// True when the document differs from what is on disk.
    bool dirty() const;
    /// The scene that Save writes: the edited level (the scene kept at Play
    /// while the simulation runs, with edits made while paused not included).
    const Scene& levelToSave() const;

    /// Unsaved-changes guard: runs `action` now when clean, else records it
    /// and asks (UiRequest::ConfirmDiscard). The UI then calls
    /// resolvePending(save / discard / cancel).
    void request(PendingAction action, std::filesystem::path file = {});
    enum class Resolution { Save, Discard, Cancel };
    void resolvePending(Resolution r);
    PendingAction pending() const { return pending_; }
    bool quitRequested() const { return quit_; }

    // ---- editing --------------------------------------------------------
    /// Runs an edit through the undo stack (see CommandStack::apply) and
    /// tells the simulation. `mergeKey` != 0 coalesces (use newMergeKey()).
    bool applyEdit(const std::string& label, const std::function<bool(Scene&)>& edit, std::uint64_t mergeKey = 0);
    /// applyEdit for an edit that can be refused: true when it changed the
    /// scene, false when it changed nothing, the edit's error when refused
    /// (the scene is then as it was).
    Result<bool> tryEdit(const std::string& label, const std::function<Result<bool>(Scene&)>& edit,
                         std::uint64_t mergeKey = 0);
    void endEdit() { commands.closeMerge(); }
    std::uint64_t newMergeKey() { return ++mergeCounter_; }
    bool undo();
    bool redo();

    /// Choosing the entity an entity-reference field (a spring end) points
    /// at: armed from the inspector, finished by clicking a body in the
    /// viewport or the entity list. Ends are picked, never typed.
    struct ReferencePick {
        const ComponentInfo* component = nullptr;
        const FieldInfo* field = nullptr;
        std::vector<Entity> entities;  ///< whose field is set
    };
    std::optional<ReferencePick> referencePick;
    void startReferencePick(const ComponentInfo& component, const FieldInfo& field, std::vector<Entity> entities);
    /// Sets the armed field to `target` as one undoable edit (refused like
    /// any inspector edit: the status names the entity and the field).
    /// Returns true when the edit was made; the pick ends either way.
    bool finishReferencePick(Entity target);

    void select(std::vector<Entity> entities);
    void selectAll();
    bool deleteSelection();
    /// What deleting `entities` takes with it, by kind, as the undo label:
    /// "delete 1 body and 1 spring".
    std::string deleteLabel(const std::vector<Entity>& entities) const;
    bool duplicateSelection();
    void copySelection();
    bool paste();
    bool hasClipboard() const { return !clipboardEntities_.empty(); }

    // ---- simulation -----------------------------------------------------
    /// Break on contact: the run pauses at the step where `body` starts
    /// touching something (null: off). A body chosen here stays watched
    /// whatever is selected later; it is cleared with the level (Open, New)
    /// and when the body is deleted. Says what is watched in the status line.
    void setBreakOnContact(Entity body);
    /// What the Viewport's toolbar shows beside "Break on contact": the
    /// watched body's name, or "off".
    std::string breakOnLabel() const;
    /// Edits made since Play (while the simulation runs): they change the
    /// running state, not the level. Reset discards them; Save writes the
    /// level as it was at Play.
    std::size_t editsSincePlay() const;
    /// The line the viewport shows while the simulation runs, saying where
    /// edits go ("" while editing):
    /// "editing the running state: Reset discards 2 edits; Save writes the level as it was at Play".
    std::string runningEditsNote() const;
    void togglePlay();
    void stepForward();
    void stepBack();
    void resetSimulation();
    /// Per displayed frame: advances the simulation, records trails.
    void update(double frameSeconds);

    // ---- input ----------------------------------------------------------
    /// Keyboard shortcut; returns true when it did something.
    bool handleShortcut(Key key, std::uint8_t mods);
    /// Mouse event in viewport pixels (origin top-left of the viewport).
    void handleViewportEvent(const InputEvent& e);
    /// Where the mouse is in the viewport (pixels), for the cursor readout.
    Vec2 mouseViewport() const { return mouse_; }
    /// Box-select rectangle in viewport pixels while dragging one.
    std::optional<std::pair<Vec2, Vec2>> selectionRect() const;
    /// First end of a spring or joint being placed.
    Entity springStart() const { return springStart_; }
    /// Joint tool: the type the next joint gets (one of jointTypeNames()).
    std::string jointType = "hinge";

    // ---- polygon tool ---------------------------------------------------
    /// 0: click the vertices (their convex hull is the shape; Enter, a
    /// click on the first vertex or a right click finishes, Esc cancels).
    /// 3..8: press at the centre of a regular polygon of that many sides and
    /// drag out its size and turn (vertex 0 follows the mouse).
    int polygonSides = 0;
    /// The shape the polygon tool would make now (world metres,
    /// counter-clockwise), for the viewport's preview; empty when none.
    std::vector<Vec2> polygonPreview() const;
    /// The vertices clicked so far (world metres).
    const std::vector<Vec2>& polygonClicks() const { return polygonClicks_; }
    /// Makes the body from the clicks (one undo step); false when they do
    /// not make a valid polygon (the status line says why).
    bool finishPolygon();
    void cancelPolygon() { polygonClicks_.clear(); }
    /// Sets the viewport size; the first call (or fitView) frames the scene.
    void setViewportSize(int width, int height);
    void fitView();

    // ---- messages -------------------------------------------------------
    std::string status;          ///< one line, bottom of the window
    /// Whether `status` says an edit was refused (the inspector shows it in
    /// red); set with the text by note and refuse, never read from it.
    bool statusRefused = false;
    std::string errorModal;      ///< non-empty: shown as a modal until dismissed
    UiRequest uiRequest = UiRequest::None;
    std::vector<std::string> log;  ///< newest last
    /// Sets the status line and logs it; `refused` marks a refusal.
    void note(std::string text, bool refused = false);
    /// Status "refused: why", not logged: a slider held past its range
    /// refuses every frame.
    void refuse(const std::string& why);

    // ---- autosave -------------------------------------------------------
    std::filesystem::path configDir;
    double autosaveSeconds = 30.0;
    /// Writes the recovery file when dirty and `autosaveSeconds` passed since
    /// the last one (clock in seconds from any origin). Returns true when it wrote.
    bool tickAutosave(double nowSeconds);
    /// A recovery file for the current document that is newer than it.
    std::optional<std::filesystem::path> recoveryAvailable() const;
    bool recover(const std::filesystem::path& recoveryFile);
    /// Deletes the document's recovery copy. Also done when the changes it
    /// holds are saved, discarded, undone back to the file's state, or
    /// replaced by another level (Open, New): a copy outlives only a crash.
    void discardRecovery();

    /// Frame input for the renderer: scene, world, overlays, camera, selection.
    render::FrameInput frameInput() const;

    /// Changes the scene was through since the last call (undo, edit, step):
    /// views compare it to refresh caches.
    std::uint64_t revision() const { return commands.revision() + revisionExtra_; }

private:
    /// Duplicate and paste: adds what `clone` creates as one edit, checked as
    /// the loader checks a file; selects the copies, or refuses, saying why.
    bool addCopies(const std::string& label, const std::function<std::vector<Entity>(Scene&)>& clone);
    void afterSceneReplaced();
    void afterUndoOrRedo();
    /// After a step back: drops the undo history past the restored step
    /// when it no longer matches the scene; what to add to the note.
    std::string forgetEditsPastStepBack();
    void forgetRecoveryWhenClean();
    /// Open and New: the new document replaces the old one with a fresh
    /// undo history, selection, trails and view.
    void replaceDocument(Document next);
    void pruneSelection();
    Vec2 snapped(Vec2 world) const;
    /// Offset that puts copies of `entities` (in `src`) under the cursor;
    /// without a cursor, `count` x (0.5, -0.5) m beside the originals.
    Vec2 placementOffset(const Registry& src, const std::vector<Entity>& entities, int count) const;
    bool mouseKnown_ = false;  ///< the cursor has been over the viewport
    double pickRadius() const;
    void placeAt(Vec2 world);

    // Tool handlers (editor/app/tools/): a left press with each tool (the
    // table in tools.cpp picks one), then the drags and releases it starts.
    friend const std::array<ToolInfo, kToolCount>& toolTable();
    void pressSelectOrRotate(const ToolPress& press);  // select_tools.cpp
    void dragMove(Vec2 world);
    void dragRotate(Vec2 world);
    void releaseBoxSelect(Vec2 px);
    void pressPlace(const ToolPress& press);           // place_tools.cpp
    void pressWall(const ToolPress& press);
    void releaseWall(Vec2 px);
    void pressSpring(const ToolPress& press);          // link_tools.cpp
    void pressJoint(const ToolPress& press);
    /// Spring and joint tools: while no first end is chosen, takes `hit` as
    /// it when it is a body (or says to click one) and returns true.
    bool takeFirstEnd(Entity hit, std::string_view toolWord, std::string_view otherwise);
    void pressBoids(const ToolPress& press);           // boids_tool.cpp
    void dragBoids(Vec2 world);
    void pressPolygon(const ToolPress& press);         // polygon_tool.cpp
    void releaseRegularPolygon();
    /// The regular polygon the current drag describes (world metres), or
    /// empty for a drag shorter than a millimetre.
    std::vector<Vec2> regularOutline() const;

    enum class Drag : std::uint8_t { None, Pan, Move, Rotate, BoxSelect, Plane, Boids, MouseSpring, RegularPolygon };
    Drag drag_ = Drag::None;
    MouseButton dragButton_ = MouseButton::Left;
    Vec2 mouse_, dragStartPx_, dragStartWorld_, lastBoid_;
    std::uint64_t dragKey_ = 0;
    std::vector<std::pair<Entity, Vec2>> dragStart_;  // entity, position at press
    std::vector<std::pair<Entity, double>> angleStart_;
    std::vector<std::pair<Entity, double>> planeStart_;
    Entity dragPrimary_;
    bool additive_ = false;
    Entity springStart_;
    std::vector<Vec2> polygonClicks_;  // polygon tool: vertices clicked so far, world metres
    std::uint32_t boidSeed_ = 12345u;

    Scene clipboard_;
    std::vector<Entity> clipboardEntities_;
    int pasteCount_ = 0;
    std::uint64_t documentSerial_ = 0;    ///< bumped when another document replaces this one
    std::uint64_t clipboardDocument_ = 0; ///< documentSerial_ when the clipboard was filled

    std::uint64_t savedCursor_ = 0;
    bool savedReachable_ = true;
    std::size_t playMark_ = 0;
    std::uint64_t mergeCounter_ = 0;
    std::uint64_t revisionExtra_ = 0;
    bool viewInitialised_ = false;

    PendingAction pending_ = PendingAction::None;
    std::filesystem::path pendingFile_;
    bool quit_ = false;
    double lastAutosave_ = -1.0;
};

} // namespace stepwise::editor
