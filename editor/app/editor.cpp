#include "app/editor.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace stepwise::editor {

Editor::Editor() : configDir(configDirectory()) {
    doc.reset(makeNewScene());
    overlays.add(render::Overlay::Velocity);
    overlays.add(render::Overlay::Contacts);
}

// ---- document ----------------------------------------------------------------

void Editor::afterSceneReplaced() {
    sim.sceneChanged();
    pruneSelection();
    ++revisionExtra_;
}

void Editor::afterUndoOrRedo() {
    // The World takes the reverted edit in place as it took the edit.
    sim.sceneEdited(doc.scene, commands.lastEdit());
    pruneSelection();
    ++revisionExtra_;
}

void Editor::note(std::string text, bool refused) {
    status = text;
    statusRefused = refused;
    log.push_back(std::move(text));
    if (log.size() > 200) log.erase(log.begin());
}

bool Editor::open(const std::filesystem::path& file) {
    Document next;
    if (Result<void> r = next.open(file); !r) {
        // The loader's message names the file and the place in it (line and
        // column, or why it cannot be read): the modal shows it whole and the
        // status line carries it too, whichever way the open was asked for.
        errorModal = r.error();
        std::string line = "open failed: " + r.error();
        std::replace(line.begin(), line.end(), '\n', ' ');
        note(std::move(line));
        return false;
    }
    replaceDocument(std::move(next));
    note("opened " + file.string());
    return true;
}

void Editor::newDocument() {
    Document next;
    next.reset(makeNewScene());
    replaceDocument(std::move(next));
    note("new level");
}

void Editor::replaceDocument(Document next) {
    // The level being replaced had its changes saved, discarded (the
    // unsaved-changes question) or had none: its recovery copy recovers
    // nothing any more, and left behind it would offer the discarded
    // changes the next time that level opens.
    discardRecovery();
    if (sim.running()) sim.reset(doc.scene);
    // A handle into the old level means nothing in the new one.
    sim.breakOnContact = {};
    sim.breakOnSensor = false;
    doc = std::move(next);
    ++documentSerial_;
    commands.clear();
    savedCursor_ = commands.absoluteCursor();
    savedReachable_ = true;
    selection.clear();
    trails = render::TrailRecorder(trails.capacity());
    viewInitialised_ = false;
    fitView();
    afterSceneReplaced();
}

const Scene& Editor::levelToSave() const { return sim.running() ? sim.editedScene() : doc.scene; }

bool Editor::saveAs(const std::filesystem::path& file) {
    // While the simulation runs, the level is the scene kept at Play: the
    // commands up to playMark_ are what is saved.
    const bool running = sim.running();
    // The recovery copy is keyed to the document's path: after a Save As
    // the old path's copy is stale (the work is in the new file), so it
    // goes too, or it would be offered the next time the old level opens.
    const std::filesystem::path previousRecovery = doc.recoveryPath(configDir);
    if (Result<void> r = doc.saveAs(levelToSave(), file); !r) {
        errorModal = "Cannot save " + file.string() + ":\n" + r.error();
        note("save failed");
        return false;
    }
    std::error_code ec;
    std::filesystem::remove(previousRecovery, ec);  // absent is fine
    savedCursor_ = running ? playMark_ : commands.absoluteCursor();
    savedReachable_ = true;
    discardRecovery();
    note(running ? "saved the edited level to " + file.string() + " (the simulation state is not part of it)"
                 : "saved " + file.string());
    return true;
}

bool Editor::save() {
    if (doc.path.empty()) {
        uiRequest = UiRequest::SaveAsDialog;
        return false;
    }
    return saveAs(doc.path);
}

bool Editor::saveStateAs(const std::filesystem::path& file) {
    if (const std::optional<Error> problem = checkSceneRelations(doc.scene)) {
        errorModal = "Cannot save the state: " + problem->message;
        return false;
    }
    // The running state with the solver's warm start (`solver_state`), so
    // that playing the saved file on gives the bits this session would.
    Scene state = doc.scene;
    state.solverState.reset();
    if (sim.running() && sim.readyToStep(doc.scene)) {
        // A settings edit wakes the sleeping islands at the next step: done
        // now, so the file resumes as this session goes on.
        sim.world()->wakeIfSettingsChanged();
        if (SolverState solver = sim.world()->solverState(); !solver.empty()) state.solverState = std::move(solver);
    }
    if (Result<void> r = saveSceneFile(state, file); !r) {
        errorModal = "Cannot save " + file.string() + ":\n" + r.error();
        return false;
    }
    note("saved the current state to " + file.string());
    return true;
}

bool Editor::dirty() const {
    const std::uint64_t here = sim.running() ? std::min<std::uint64_t>(playMark_, commands.absoluteCursor())
                                             : commands.absoluteCursor();
    return !savedReachable_ || here != savedCursor_;
}

void Editor::request(PendingAction action, std::filesystem::path file) {
    pending_ = action;
    pendingFile_ = std::move(file);
    if (dirty()) {
        uiRequest = UiRequest::ConfirmDiscard;
        return;
    }
    resolvePending(Resolution::Discard);
}

void Editor::resolvePending(Resolution r) {
    const PendingAction action = pending_;
    pending_ = PendingAction::None;
    if (uiRequest == UiRequest::ConfirmDiscard) uiRequest = UiRequest::None;
    if (r == Resolution::Cancel) return;
    if (r == Resolution::Save && !save()) return;  // a failed save keeps the document open
    switch (action) {
    case PendingAction::New: newDocument(); break;
    case PendingAction::Open: open(pendingFile_); break;
    case PendingAction::Quit:
        discardRecovery();
        quit_ = true;
        break;
    case PendingAction::None: break;
    }
}

// ---- editing ---------------------------------------------------------------------

void Editor::refuse(const std::string& why) {
    status = "refused: " + why;
    statusRefused = true;
}

bool Editor::applyEdit(const std::string& label, const std::function<bool(Scene&)>& edit, std::uint64_t mergeKey) {
    if (commands.absoluteCursor() < savedCursor_) savedReachable_ = false;  // the saved state leaves the redo branch
    sim.beforeEdit(commands.cursor());
    if (!commands.apply(doc.scene, label, edit, mergeKey)) return false;
    sim.sceneEdited(doc.scene, commands.lastEdit());
    pruneSelection();
    status = label;
    statusRefused = false;
    return true;
}

Result<bool> Editor::tryEdit(const std::string& label, const std::function<Result<bool>(Scene&)>& edit,
                             std::uint64_t mergeKey) {
    std::optional<Error> refused;
    const bool applied = applyEdit(label, [&](Scene& s) {
        Result<bool> changed = edit(s);
        if (!changed) refused = changed.failure();
        return changed && *changed;
    }, mergeKey);
    if (refused) return *refused;
    return applied;
}

bool Editor::undo() {
    if (sim.running() && commands.cursor() <= playMark_) {
        note("nothing to undo since Play (R resets to the edited level)");
        return false;
    }
    if (!commands.entitiesAsLeft(doc.scene, false)) {
        note("undo refused: the run added or removed entities since that edit (an emitter's copies, a broken joint); "
             "R resets to the edited level",
             true);
        return false;
    }
    const std::string label = commands.undo(doc.scene);
    if (label.empty()) return false;
    afterUndoOrRedo();
    // Back to the state before the run's edits with no step between: the
    // islands they woke sleep again and the contacts are those of before.
    if (sim.running()) sim.undoneTo(doc.scene, commands.cursor());
    forgetRecoveryWhenClean();
    note("undo: " + label);
    return true;
}

bool Editor::redo() {
    if (!commands.entitiesAsLeft(doc.scene, true)) {
        note("redo refused: the run added or removed entities since that edit was undone (an emitter's copies, a "
             "broken joint)",
             true);
        return false;
    }
    const std::string label = commands.redo(doc.scene);
    if (label.empty()) return false;
    afterUndoOrRedo();
    forgetRecoveryWhenClean();
    note("redo: " + label);
    return true;
}

void Editor::forgetRecoveryWhenClean() {
    // Back at the file's own state (undo, redo or Reset got there): the
    // recovery copy holds changes that are no longer wanted.
    if (!dirty()) discardRecovery();
}

void Editor::pruneSelection() {
    std::erase_if(selection, [&](Entity e) { return !doc.scene.registry.alive(e); });
    if (!doc.scene.registry.alive(springStart_)) springStart_ = {};
    if (!sim.breakOnContact.isNull() && !doc.scene.registry.alive(sim.breakOnContact)) sim.breakOnContact = {};
}

void Editor::startReferencePick(const ComponentInfo& component, const FieldInfo& field, std::vector<Entity> entities) {
    referencePick = ReferencePick{&component, &field, std::move(entities)};
    note("pick " + std::string(component.name) + "." + std::string(field.key) +
         ": click a body in the viewport or the entity list (Esc cancels)");
}

bool Editor::finishReferencePick(Entity target) {
    if (!referencePick) return false;
    const ReferencePick p = *referencePick;
    referencePick.reset();
    if (!isBody(doc.scene.registry, target)) {
        note("pick cancelled: " + displayName(doc.scene.registry, target) + " is not a body");
        return false;
    }
    const std::string what = "set " + std::string(p.component->name) + "." + std::string(p.field->key) + " to " +
                             displayName(doc.scene.registry, target);
    const Result<bool> edited =
        tryEdit(what, [&](Scene& s) { return changedAny(setFieldOnAll(s, *p.component, *p.field, target, p.entities)); });
    if (edited && *edited) return true;
    if (edited) {
        status = "nothing changed";
        statusRefused = false;
    } else {
        refuse(edited.error());
    }
    return false;
}

void Editor::select(std::vector<Entity> entities) {
    selection = std::move(entities);
    pruneSelection();
}

void Editor::selectAll() { select(doc.scene.registry.entities()); }

Vec2 Editor::placementOffset(const Registry& src, const std::vector<Entity>& entities, int count) const {
    // The copies' centre goes under the cursor (snapped like a placement);
    // with no cursor over the viewport yet, beside the originals.
    Vec2 sum;
    int n = 0;
    for (Entity e : entities)
        if (const Position* p = src.tryGet<Position>(e)) {
            sum += p->value;
            ++n;
        }
    if (!mouseKnown_ || n == 0) return Vec2{0.5 * count, -0.5 * count};
    return snapped(view.toWorld(mouse_)) - sum / double(n);
}

std::string Editor::deleteLabel(const std::vector<Entity>& doomed) const {
    // Says what goes, by kind: "delete 1 body and 1 spring",
    // "delete 1 body and 2 joints".
    const Registry& reg = doc.scene.registry;
    std::size_t bodies = 0, springs = 0, joints = 0, walls = 0, others = 0;
    std::vector<Entity> all = doomed;
    for (Entity s : attachedTo(reg, doomed)) all.push_back(s);
    for (Entity e : all) {
        if (!reg.alive(e)) continue;
        if (reg.has<Spring>(e)) ++springs;
        else if (reg.has<Joint>(e)) ++joints;
        else if (reg.has<Plane>(e)) ++walls;
        else if (isBody(reg, e)) ++bodies;
        else ++others;
    }
    std::vector<std::string> parts;
    auto add = [&](std::size_t n, const char* one, const char* many) {
        if (n) parts.push_back(std::to_string(n) + " " + (n == 1 ? one : many));
    };
    add(bodies, "body", "bodies");
    add(springs, "spring", "springs");
    add(joints, "joint", "joints");
    add(walls, "wall", "walls");
    add(others, "entity", "entities");
    std::string label = "delete ";
    for (std::size_t i = 0; i < parts.size(); ++i)
        label += (i == 0 ? "" : i + 1 == parts.size() ? " and " : ", ") + parts[i];
    return label;
}

bool Editor::deleteSelection() {
    if (selection.empty()) return false;
    const std::vector<Entity> doomed = selection;
    const bool done = applyEdit(deleteLabel(doomed), [&](Scene& s) { return destroyWithSprings(s, doomed) > 0; });
    selection.clear();
    return done;
}

bool Editor::addCopies(const std::string& label, const std::function<std::vector<Entity>(Scene&)>& clone) {
    // Copies are checked as a loaded file is, so that what the editor makes
    // always saves and loads.
    std::vector<Entity> created;
    const Result<bool> edited = tryEdit(label, [&](Scene& s) -> Result<bool> {
        created = clone(s);
        if (created.empty()) return false;
        if (std::optional<Error> problem = checkEdited(s, created, label)) return *problem;
        return true;
    });
    if (!edited) {
        refuse(label + ": " + edited.error());
        return false;
    }
    if (*edited) selection = created;
    return *edited;
}

bool Editor::duplicateSelection() {
    if (selection.empty()) return false;
    const std::vector<Entity> source = selection;
    return addCopies("duplicate", [&](Scene& s) {
        const Registry copy = s.registry;  // read from a stable copy while creating
        return cloneEntities(copy, source, s, placementOffset(copy, source, 1));
    });
}

void Editor::copySelection() {
    clipboard_ = Scene{};
    clipboardEntities_ = cloneEntities(doc.scene.registry, selection, clipboard_, {0.0, 0.0}, OutsideRefs::Carry);
    clipboardDocument_ = documentSerial_;
    pasteCount_ = 0;
    note("copied " + std::to_string(clipboardEntities_.size()) + " entities");
}

bool Editor::paste() {
    if (clipboardEntities_.empty()) return false;
    ++pasteCount_;
    const Vec2 offset = placementOffset(clipboard_.registry, clipboardEntities_, pasteCount_);
    return addCopies("paste", [&](Scene& s) {
        // Handles to bodies outside the copy mean something only in the
        // document they were copied from.
        return cloneEntities(clipboard_.registry, clipboardEntities_, s, offset,
                             clipboardDocument_ == documentSerial_ ? OutsideRefs::Keep : OutsideRefs::Drop);
    });
}

// ---- simulation ------------------------------------------------------------------

void Editor::setBreakOnContact(Entity body) {
    sim.breakOnContact = doc.scene.registry.alive(body) ? body : Entity{};
    note(sim.breakOnContact.isNull() ? std::string("break on contact: off")
                                     : "break on contact: watching " + breakOnLabel());
}

std::string Editor::breakOnLabel() const {
    return sim.breakOnContact.isNull() ? std::string("off") : displayName(doc.scene.registry, sim.breakOnContact);
}

std::size_t Editor::editsSincePlay() const {
    return sim.running() && commands.cursor() > playMark_ ? commands.cursor() - playMark_ : 0;
}

std::string Editor::runningEditsNote() const {
    if (!sim.running()) return {};
    const std::size_t n = editsSincePlay();
    return "editing the running state: Reset discards " +
           (n == 0 ? std::string("any edit") : std::to_string(n) + (n == 1 ? " edit" : " edits")) +
           "; Save writes the level as it was at Play";
}

void Editor::togglePlay() {
    if (sim.state() == SimState::Playing) {
        sim.pause();
        note("paused at t = " + std::to_string(doc.scene.world.time) + " s");
        return;
    }
    const bool fromEditing = sim.state() == SimState::Editing;
    if (fromEditing) playMark_ = commands.cursor();
    if (!sim.play(doc.scene)) {
        errorModal = sim.message();
        note(sim.message());
        return;
    }
    if (fromEditing) trails = render::TrailRecorder(trails.capacity());
    note("playing");
}

void Editor::stepForward() {
    if (sim.state() == SimState::Editing) {
        playMark_ = commands.cursor();
        trails = render::TrailRecorder(trails.capacity());
    }
    sim.setCommandCursor(commands.absoluteCursor());
    if (!sim.step(doc.scene) && !sim.message().empty()) note(sim.message());
    for (std::string& line : sim.takeBreakNotes()) note(std::move(line));
    if (const World* w = sim.world()) trails.record(*w);
    ++revisionExtra_;
}

void Editor::stepBack() {
    if (sim.stepBack(doc.scene)) {
        note("stepped back to t = " + std::to_string(doc.scene.world.time) + " s" + forgetEditsPastStepBack());
        ++revisionExtra_;
        pruneSelection();
    } else {
        note(sim.running() ? "no earlier state in the history" : "step back works while the simulation runs");
    }
}

std::string Editor::forgetEditsPastStepBack() {
    // The restored scene is the one of that step's time: an edit made
    // after it is not in it, and one undone since is. The undo history past
    // that point no longer describes the scene (an undo would restore a body
    // the scene does not have), so it goes, as reset drops the edits made
    // while running.
    const std::uint64_t restored = sim.restoredCommandCursor(), here = commands.absoluteCursor();
    if (restored == here) return {};
    // Edits made after the step, since play: the history up to the step
    // stays. Otherwise (an edit undone since, or one from before play that
    // Reset would bring back) none of it matches both the restored scene
    // and the level Reset returns to: all of it goes.
    const std::uint64_t dropped = here - commands.cursor();
    const std::size_t before = commands.size();
    if (restored < here && restored >= dropped + playMark_) {
        commands.truncate(std::size_t(restored - dropped));
    } else {
        commands.clear();
        playMark_ = 0;
    }
    if (commands.absoluteCursor() < savedCursor_) savedReachable_ = false;
    const std::size_t forgotten = before - commands.size();
    return "; the undo history past that step is cleared (" + std::to_string(forgotten) +
           (forgotten == 1 ? " edit)" : " edits)");
}

void Editor::resetSimulation() {
    const std::size_t discarded = editsSincePlay();
    if (!sim.reset(doc.scene)) return;
    // Edits made while paused applied to the simulated state: they go with it.
    commands.truncate(playMark_);
    trails = render::TrailRecorder(trails.capacity());
    afterSceneReplaced();
    forgetRecoveryWhenClean();
    note(discarded == 0 ? std::string("reset to the edited level")
                        : "reset to the edited level; discarded " + std::to_string(discarded) +
                              (discarded == 1 ? " edit" : " edits") + " made while running");
}

void Editor::update(double frameSeconds) {
    const std::uint64_t before = sim.steps();
    const bool wasPlaying = sim.state() == SimState::Playing;
    sim.setCommandCursor(commands.absoluteCursor());
    sim.advance(doc.scene, frameSeconds);
    for (std::string& line : sim.takeBreakNotes()) note(std::move(line));
    if (sim.steps() != before) {
        ++revisionExtra_;
        if (const World* w = sim.world()) trails.record(*w);
    }
    if (wasPlaying && sim.state() == SimState::Paused && !sim.message().empty()) {
        note(sim.message());
        if (sim.contactPair) selection = {sim.contactPair->first, sim.contactPair->second};
        pruneSelection();
    }
}

// ---- input -----------------------------------------------------------------------

bool Editor::handleShortcut(Key key, std::uint8_t mods) {
    const bool ctrl = (mods & kModCtrl) != 0, shift = (mods & kModShift) != 0;
    if (ctrl) {
        switch (key) {
        case Key::Z:
            return shift ? redo() : undo();
        case Key::Y: return redo();
        case Key::S:
            if (shift) uiRequest = UiRequest::SaveAsDialog;
            else save();
            return true;
        case Key::O: uiRequest = UiRequest::OpenDialog; return true;
        case Key::N: request(PendingAction::New); return true;
        case Key::Q: request(PendingAction::Quit); return true;
        case Key::D: return duplicateSelection();
        case Key::C: copySelection(); return true;
        case Key::V: return paste();
        case Key::A: selectAll(); return true;
        default: return false;
        }
    }
    switch (key) {
    case Key::Space: togglePlay(); return true;
    case Key::Right: stepForward(); return true;
    case Key::Left: stepBack(); return true;
    case Key::R: resetSimulation(); return true;
    case Key::Delete:
    case Key::Backspace: return deleteSelection();
    case Key::Enter:
        if (tool == Tool::Polygon && !polygonClicks_.empty()) {
            finishPolygon();
            return true;
        }
        break;
    case Key::Escape:
        springStart_ = {};
        polygonClicks_.clear();
        if (referencePick) {
            referencePick.reset();
            note("pick cancelled");
            return true;
        }
        if (drag_ == Drag::None) selection.clear();
        return true;
    case Key::F1: uiRequest = UiRequest::Help; return true;
    case Key::F: fitView(); return true;
    case Key::G: snap = !snap; note(snap ? "snap on" : "snap off"); return true;
    default: break;
    }
    if (const std::optional<Tool> picked = toolForKey(key)) {
        tool = *picked;
        springStart_ = {};
        polygonClicks_.clear();
        note(std::string("tool: ") + std::string(toolName(tool)));
        return true;
    }
    return false;
}

void Editor::setViewportSize(int width, int height) {
    view.width = std::max(1, width);
    view.height = std::max(1, height);
    if (!viewInitialised_) fitView();
}

void Editor::fitView() {
    view.camera = render::sceneCamera(doc.scene, view.width, view.height);
    viewInitialised_ = true;
}

Vec2 Editor::snapped(Vec2 w) const {
    if (!snap || !(snapSpacing > 0.0)) return w;
    return {std::round(w.x / snapSpacing) * snapSpacing, std::round(w.y / snapSpacing) * snapSpacing};
}

double Editor::pickRadius() const { return 6.0 / view.pixelsPerMetre(); }  // six pixels

std::optional<std::pair<Vec2, Vec2>> Editor::selectionRect() const {
    if (drag_ != Drag::BoxSelect) return std::nullopt;
    return std::make_pair(dragStartPx_, mouse_);
}

void Editor::handleViewportEvent(const InputEvent& e) {
    using T = InputEvent::Type;
    const Vec2 px{e.x, e.y};
    switch (e.type) {
    case T::Wheel:
        view.zoomAt(px, e.wheel);
        return;
    case T::MouseDown: {
        mouse_ = px;
        mouseKnown_ = true;
        dragStartPx_ = px;
        dragButton_ = e.button;
        const Vec2 world = view.toWorld(px);
        dragStartWorld_ = world;
        if (e.button == MouseButton::Right && tool == Tool::Polygon && polygonSides == 0 && !polygonClicks_.empty()) {
            finishPolygon();  // right click ends the outline
            return;
        }
        if (e.button != MouseButton::Left) {
            drag_ = Drag::Pan;
            return;
        }
        additive_ = (e.mods & (kModShift | kModCtrl)) != 0;
        Entity hit = pick(doc.scene, world, pickRadius());
        if (referencePick) {
            // Whatever the tool: this click answers the inspector's pick.
            if (hit.isNull()) note("pick: no body there (Esc cancels)");
            else finishReferencePick(hit);
            return;
        }
        if (tool < Tool::Count) (this->*toolTable()[std::size_t(tool)].press)(ToolPress{px, world, hit});
        return;
    }
    case T::MouseMove: {
        const Vec2 prev = mouse_;
        mouse_ = px;
        mouseKnown_ = true;
        const Vec2 world = view.toWorld(px);
        switch (drag_) {
        case Drag::Pan: view.pan(px - prev); return;
        case Drag::MouseSpring:
            if (sim.mouseSpring) sim.mouseSpring->second = world;
            return;
        case Drag::Move: dragMove(world); return;
        case Drag::Rotate: dragRotate(world); return;
        case Drag::Boids: dragBoids(world); return;
        default: return;
        }
    }
    case T::MouseUp: {
        mouse_ = px;
        mouseKnown_ = true;
        const Drag finished = drag_;
        drag_ = Drag::None;
        endEdit();
        if (finished == Drag::MouseSpring) {
            sim.mouseSpring.reset();
            sim.sceneChanged();
        } else if (finished == Drag::BoxSelect) {
            releaseBoxSelect(px);
        } else if (finished == Drag::RegularPolygon) {
            releaseRegularPolygon();
        } else if (finished == Drag::Plane) {
            releaseWall(px);
        }
        return;
    }
    default: return;
    }
}

// ---- autosave --------------------------------------------------------------------

bool Editor::tickAutosave(double nowSeconds) {
    if (lastAutosave_ < 0.0) lastAutosave_ = nowSeconds;
    if (nowSeconds - lastAutosave_ < autosaveSeconds) return false;
    lastAutosave_ = nowSeconds;
    if (!dirty()) return false;
    const std::filesystem::path file = doc.recoveryPath(configDir);
    std::error_code ec;
    std::filesystem::create_directories(file.parent_path(), ec);
    if (Result<void> r = writeFileAtomically(file, sceneToJsonText(levelToSave())); !r) {
        note("autosave failed: " + r.error());
        return false;
    }
    note("autosaved to " + file.string());
    return true;
}

std::optional<std::filesystem::path> Editor::recoveryAvailable() const {
    const std::filesystem::path file = doc.recoveryPath(configDir);
    std::error_code ec;
    if (!std::filesystem::exists(file, ec)) return std::nullopt;
    if (!doc.path.empty() && std::filesystem::exists(doc.path, ec) &&
        std::filesystem::last_write_time(file, ec) < std::filesystem::last_write_time(doc.path, ec))
        return std::nullopt;  // the level was saved after the recovery copy: nothing to recover
    return file;
}

bool Editor::recover(const std::filesystem::path& recoveryFile) {
    Result<Scene> loaded = loadSceneFile(recoveryFile);
    if (!loaded) {
        errorModal = "The recovery file cannot be read:\n" + loaded.error();
        return false;
    }
    // One undoable step from the file on disk to the recovered level, which
    // leaves the document dirty until saved.
    Scene recovered = std::move(*loaded);
    applyEdit("recover unsaved changes", [&](Scene& s) {
        s = std::move(recovered);
        return true;
    });
    note("recovered unsaved changes from " + recoveryFile.string());
    return true;
}

void Editor::discardRecovery() {
    std::error_code ec;
    std::filesystem::remove(doc.recoveryPath(configDir), ec);
}

render::FrameInput Editor::frameInput() const {
    render::FrameInput in;
    in.scene = &doc.scene;
    in.world = sim.world();
    if (in.world) in.contacts = sim.contacts();
    in.overlays = overlays;
    if (!in.world) in.overlays.bits &= ~(std::uint32_t(render::Overlay::Force) | std::uint32_t(render::Overlay::ForceField) |
                                         std::uint32_t(render::Overlay::Contacts) | std::uint32_t(render::Overlay::Joints));
    in.camera = view.camera;
    in.selection = selection;
    if (!springStart_.isNull()) in.selection.push_back(springStart_);
    in.polygonPreview = polygonPreview();
    in.polygonClicks = polygonClicks_;
    in.trails = sim.running() ? &trails : nullptr;
    if (!in.trails) in.overlays.bits &= ~std::uint32_t(render::Overlay::Trails);
    in.hud = true;
    return in;
}

} // namespace stepwise::editor
