#include "app/editor.hpp"

#include "app/scene_edit.hpp"

#include "stepwise/components.hpp"
#include "stepwise/scene_io.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace stepwise::editor {

std::string_view toolName(Tool t) {
    switch (t) {
    case Tool::Select: return "Select";
    case Tool::Rotate: return "Rotate";
    case Tool::Circle: return "Circle";
    case Tool::Box: return "Box";
    case Tool::Plane: return "Wall";
    case Tool::Spring: return "Spring";
    case Tool::Attractor: return "Attractor";
    case Tool::Boids: return "Boids";
    case Tool::Joint: return "Joint";
    case Tool::Polygon: return "Polygon";
    case Tool::Count: break;
    }
    return "?";
}

// Keys 1..9 pick the first nine tools and 0 the tenth, as on a keyboard's row.
Key toolKey(Tool t) {
    return std::uint16_t(t) < 9 ? Key(std::uint16_t(Key::Num1) + std::uint16_t(t)) : Key::Num0;
}

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

void Editor::note(std::string text) {
    status = text;
    log.push_back(std::move(text));
    if (log.size() > 200) log.erase(log.begin());
}

bool Editor::open(const std::filesystem::path& file) {
    Document next;
    if (Result<void> r = next.open(file); !r) {
        errorModal = r.error();
        note("open failed: " + file.string());
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
    if (sim.running()) sim.reset(doc.scene);
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
    if (sim.running() && sim.ensureWorld(doc.scene))
        if (SolverState solver = sim.world()->solverState(); !solver.empty()) state.solverState = std::move(solver);
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

bool Editor::applyEdit(const std::string& label, const std::function<bool(Scene&)>& edit, std::uint64_t mergeKey) {
    if (commands.absoluteCursor() < savedCursor_) savedReachable_ = false;  // the saved state leaves the redo branch
    if (!commands.apply(doc.scene, label, edit, mergeKey)) return false;
    sim.sceneChanged();
    pruneSelection();
    status = label;
    return true;
}

bool Editor::undo() {
    if (sim.running() && commands.cursor() <= playMark_) {
        note("nothing to undo since Play (R resets to the edited level)");
        return false;
    }
    const std::string label = commands.undo(doc.scene);
    if (label.empty()) return false;
    afterSceneReplaced();
    note("undo: " + label);
    return true;
}

bool Editor::redo() {
    const std::string label = commands.redo(doc.scene);
    if (label.empty()) return false;
    afterSceneReplaced();
    note("redo: " + label);
    return true;
}

void Editor::pruneSelection() {
    std::erase_if(selection, [&](Entity e) { return !doc.scene.registry.alive(e); });
    if (!doc.scene.registry.alive(springStart_)) springStart_ = {};
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
    std::string problem;
    const std::string what = "set " + std::string(p.component->name) + "." + std::string(p.field->key) + " to " +
                             displayName(doc.scene.registry, target);
    if (applyEdit(what, [&](Scene& s) { return setFieldOnAll(s, *p.component, *p.field, target, p.entities, &problem) > 0; }))
        return true;
    status = problem.empty() ? "nothing changed" : "refused: " + problem;
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
    // Says what goes, by kind: "delete 1 body and 1 spring".
    const Registry& reg = doc.scene.registry;
    std::size_t bodies = 0, springs = 0, walls = 0, others = 0;
    std::vector<Entity> all = doomed;
    for (Entity s : attachedTo(reg, doomed)) all.push_back(s);
    for (Entity e : all) {
        if (!reg.alive(e)) continue;
        if (reg.has<Spring>(e)) ++springs;
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

bool Editor::duplicateSelection() {
    if (selection.empty()) return false;
    std::vector<Entity> created;
    const std::vector<Entity> source = selection;
    const bool done = applyEdit("duplicate", [&](Scene& s) {
        const Registry copy = s.registry;  // read from a stable copy while creating
        created = cloneEntities(copy, source, s, placementOffset(copy, source, 1));
        return !created.empty();
    });
    if (done) selection = created;
    return done;
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
    std::vector<Entity> created;
    const Vec2 offset = placementOffset(clipboard_.registry, clipboardEntities_, pasteCount_);
    const bool done = applyEdit("paste", [&](Scene& s) {
        // Handles to bodies outside the copy mean something only in the
        // document they were copied from.
        created = cloneEntities(clipboard_.registry, clipboardEntities_, s, offset,
                                clipboardDocument_ == documentSerial_ ? OutsideRefs::Keep : OutsideRefs::Drop);
        return !created.empty();
    });
    if (done) selection = created;
    return done;
}

// ---- simulation ------------------------------------------------------------------

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
    if (!sim.step(doc.scene) && !sim.message().empty()) note(sim.message());
    if (const World* w = sim.world()) trails.record(*w);
    ++revisionExtra_;
}

void Editor::stepBack() {
    if (sim.stepBack(doc.scene)) {
        note("stepped back to t = " + std::to_string(doc.scene.world.time) + " s");
        ++revisionExtra_;
        pruneSelection();
    } else {
        note(sim.running() ? "no earlier state in the history" : "step back works while the simulation runs");
    }
}

void Editor::resetSimulation() {
    if (!sim.reset(doc.scene)) return;
    // Edits made while paused applied to the simulated state: they go with it.
    commands.truncate(playMark_);
    trails = render::TrailRecorder(trails.capacity());
    afterSceneReplaced();
    note("reset to the edited level");
}

void Editor::update(double frameSeconds) {
    const std::uint64_t before = sim.steps();
    const bool wasPlaying = sim.state() == SimState::Playing;
    sim.advance(doc.scene, frameSeconds);
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
    if (key >= Key::Num0 && key <= Key::Num9 &&
        (key == Key::Num0 ? std::uint16_t(Tool::Count) > 9
                          : std::uint16_t(key) - std::uint16_t(Key::Num1) < std::uint16_t(Tool::Count))) {
        tool = key == Key::Num0 ? Tool(9) : Tool(std::uint16_t(key) - std::uint16_t(Key::Num1));
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

void Editor::placeAt(Vec2 world) {
    const Vec2 at = snapped(world);
    Entity created;
    const std::string label = std::string("place ") + std::string(toolName(tool));
    const bool done = applyEdit(label, [&](Scene& s) {
        switch (tool) {
        case Tool::Circle: created = addCircle(s, at); break;
        case Tool::Box: created = addBox(s, at); break;
        case Tool::Attractor: created = addAttractor(s, at); break;
        default: return false;
        }
        return true;
    });
    if (done) selection = {created};
}

void Editor::handleViewportEvent(const InputEvent& e) {
    using T = InputEvent::Type;
    const Vec2 px{e.x, e.y};
    const Registry& reg = doc.scene.registry;
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
        switch (tool) {
        case Tool::Select:
        case Tool::Rotate: {
            if (hit.isNull() && tool == Tool::Rotate && !selection.empty() && !additive_) {
                hit = selection.front();  // rotate the selection about its first entity from anywhere
            } else if (hit.isNull()) {
                if (!additive_) selection.clear();
                drag_ = Drag::BoxSelect;
                return;
            }
            const bool selected = std::find(selection.begin(), selection.end(), hit) != selection.end();
            if (additive_) {
                if (selected) std::erase(selection, hit);
                else selection.push_back(hit);
                return;
            }
            if (!selected) selection = {hit};
            dragPrimary_ = hit;
            dragKey_ = newMergeKey();
            if (sim.state() == SimState::Playing && tool == Tool::Select && reg.has<Position>(hit) &&
                !(reg.has<Static>(hit) && reg.tryGet<Static>(hit)->value)) {
                // Playing: a mouse spring, not an edit.
                drag_ = Drag::MouseSpring;
                sim.mouseSpring = std::make_pair(hit, world);
                return;
            }
            dragStart_.clear();
            angleStart_.clear();
            planeStart_.clear();
            for (Entity s : selection) {
                if (const Position* p = reg.tryGet<Position>(s)) dragStart_.push_back({s, p->value});
                if (const Plane* pl = reg.tryGet<Plane>(s)) planeStart_.push_back({s, pl->offset});
                if (reg.has<Box>(s) || reg.has<Polygon>(s) || reg.has<Angle>(s)) {
                    const Angle* a = reg.tryGet<Angle>(s);
                    angleStart_.push_back({s, a ? a->value : 0.0});
                }
            }
            drag_ = tool == Tool::Rotate ? Drag::Rotate : Drag::Move;
            return;
        }
        case Tool::Circle:
        case Tool::Box:
        case Tool::Attractor: placeAt(world); return;
        case Tool::Plane: drag_ = Drag::Plane; return;
        case Tool::Spring: {
            if (springStart_.isNull()) {
                if (!hit.isNull() && isBody(reg, hit)) {
                    springStart_ = hit;
                    note("spring: click a second body, or empty space for an anchor (Esc cancels)");
                } else {
                    note("spring: click a body first");
                }
                return;
            }
            const Entity a = springStart_;
            springStart_ = {};
            Entity created;
            const bool toBody = !hit.isNull() && hit != a && isBody(reg, hit);
            const Vec2 anchor = snapped(world);
            if (applyEdit("place spring", [&](Scene& s) {
                    created = toBody ? addSpring(s, a, hit) : addAnchoredSpring(s, a, anchor);
                    return true;
                }))
                selection = {created};
            return;
        }
        case Tool::Joint: {
            // First click: body a. Second click: body b, or empty space for
            // the world; the second click's point is the anchor (for
            // distance and rope, b's end: a's end is its centre).
            if (springStart_.isNull()) {
                if (!hit.isNull() && isBody(reg, hit)) {
                    springStart_ = hit;
                    note("joint: click a second body, or empty space to join to the world (Esc cancels)");
                } else {
                    note("joint: click a body first");
                }
                return;
            }
            const Entity a = springStart_;
            springStart_ = {};
            const Entity b = !hit.isNull() && hit != a && isBody(reg, hit) ? hit : Entity{};
            Entity created;
            std::string problem;
            if (applyEdit("place " + jointType + " joint", [&](Scene& s) {
                    created = addJoint(s, jointType, a, b, snapped(world), &problem);
                    return !created.isNull();
                }))
                selection = {created};
            else if (!problem.empty())
                note("joint refused: " + problem);
            return;
        }
        case Tool::Boids: {
            drag_ = Drag::Boids;
            dragKey_ = newMergeKey();
            lastBoid_ = snapped(world);
            Entity created;
            applyEdit("boid brush", [&](Scene& s) {
                created = addBoid(s, lastBoid_, {1.0, 0.0});
                return true;
            }, dragKey_);
            return;
        }
        case Tool::Polygon: {
            const Vec2 at = snapped(world);
            if (polygonSides >= 3) {
                drag_ = Drag::RegularPolygon;
                dragStartWorld_ = at;
                return;
            }
            // A click on the first vertex closes the outline.
            if (polygonClicks_.size() >= 3 && length(px - view.toPixels(polygonClicks_.front())) <= 8.0) {
                finishPolygon();
                return;
            }
            std::vector<Vec2> next = polygonClicks_;
            next.push_back(at);
            if (convexHull(next).size() > 8) {
                note("polygon: at most 8 vertices; press Enter to make it");
                return;
            }
            polygonClicks_ = std::move(next);
            note("polygon: " + std::to_string(polygonClicks_.size()) +
                 " clicked; click more, then Enter, a right click or the first vertex (Esc cancels)");
            return;
        }
        case Tool::Count: return;
        }
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
        case Drag::Move: {
            Vec2 offset = world - dragStartWorld_;
            // Snap the grabbed entity's position to the grid; the rest keep
            // their offsets to it.
            for (const auto& [ent, start] : dragStart_)
                if (ent == dragPrimary_) offset = snapped(start + offset) - start;
            if (offset == Vec2{}) return;
            applyEdit("move", [&](Scene& s) {
                for (const auto& [ent, start] : dragStart_)
                    if (Position* p = s.registry.tryGet<Position>(ent)) p->value = start + offset;
                for (const auto& [ent, off0] : planeStart_)
                    if (Plane* pl = s.registry.tryGet<Plane>(ent)) pl->offset = off0 + dot(pl->normal, offset);
                return true;
            }, dragKey_);
            return;
        }
        case Drag::Rotate: {
            const Position* p = reg.tryGet<Position>(dragPrimary_);
            if (!p) return;
            const Vec2 a = dragStartWorld_ - p->value, b = world - p->value;
            double delta = std::atan2(cross(a, b), dot(a, b));
            if (snap) delta = std::round(delta / (std::numbers::pi / 12.0)) * (std::numbers::pi / 12.0);  // 15 degrees
            applyEdit("rotate", [&](Scene& s) {
                for (const auto& [ent, start] : angleStart_) s.registry.emplace(ent, Angle{start + delta});
                return !angleStart_.empty();
            }, dragKey_);
            return;
        }
        case Drag::Boids: {
            const Vec2 at = snapped(world);
            const Vec2 d = at - lastBoid_;
            const double l = length(d);
            if (l < 0.6) return;  // brush spacing, metres
            // Deterministic jitter (LCG) so a brush stroke is not a line.
            boidSeed_ = boidSeed_ * 1664525u + 1013904223u;
            const double jitter = (double(boidSeed_ >> 8) / double(1u << 24) - 0.5) * 0.4;
            const Vec2 dir = d / l;
            const Vec2 pos = at + Vec2{-dir.y, dir.x} * jitter;
            lastBoid_ = at;
            applyEdit("boid brush", [&](Scene& s) {
                addBoid(s, pos, dir * 2.0);
                return true;
            }, dragKey_);
            return;
        }
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
            if (length(px - dragStartPx_) < 3.0) return;  // a click on empty space: selection already cleared
            std::vector<Entity> inside = entitiesInRect(doc.scene, dragStartWorld_, view.toWorld(px));
            if (additive_) {
                for (Entity ent : inside)
                    if (std::find(selection.begin(), selection.end(), ent) == selection.end()) selection.push_back(ent);
            } else {
                selection = std::move(inside);
            }
        } else if (finished == Drag::RegularPolygon) {
            const std::vector<Vec2> outline = regularOutline();
            if (outline.empty()) {
                note("polygon: drag out its size from the centre");
                return;
            }
            Entity created;
            std::string problem;
            if (applyEdit("place polygon", [&](Scene& s) {
                    created = addPolygon(s, outline, &problem);
                    return !created.isNull();
                }))
                selection = {created};
            else if (!problem.empty())
                note("refused: " + problem);
        } else if (finished == Drag::Plane) {
            const Vec2 world = view.toWorld(px);
            const Vec2 through = snapped(dragStartWorld_);
            // Dragging points the normal (the side bodies stay on); a click
            // makes a floor.
            const Vec2 normal = length(px - dragStartPx_) > 5.0 ? world - dragStartWorld_ : Vec2{0.0, 1.0};
            Entity created;
            if (applyEdit("place wall", [&](Scene& s) {
                    created = addPlane(s, through, normal);
                    return true;
                }))
                selection = {created};
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

std::vector<Vec2> Editor::polygonPreview() const {
    if (tool != Tool::Polygon) return {};
    const Vec2 cursor = snapped(view.toWorld(mouse_));
    if (polygonSides >= 3) return drag_ == Drag::RegularPolygon ? regularOutline() : std::vector<Vec2>{};
    if (polygonClicks_.empty()) return {};
    // The hull with the cursor as the next vertex, unless that breaks the limit.
    std::vector<Vec2> points = polygonClicks_;
    points.push_back(cursor);
    std::vector<Vec2> hull = convexHull(points);
    if (hull.size() > 8 || hull.size() < 3) hull = convexHull(polygonClicks_);
    return hull;
}

std::vector<Vec2> Editor::regularOutline() const {
    const Vec2 arm = snapped(view.toWorld(mouse_)) - dragStartWorld_;
    const double radius = length(arm);
    if (!(radius > 1e-3) || polygonSides < 3) return {};  // a click, not a drag
    std::vector<Vec2> outline = regularPolygon(polygonSides, radius, std::atan2(arm.y, arm.x));
    for (Vec2& v : outline) v += dragStartWorld_;
    return outline;
}

bool Editor::finishPolygon() {
    const std::vector<Vec2> hull = convexHull(polygonClicks_);
    polygonClicks_.clear();
    std::string problem;
    Entity created;
    if (hull.size() < 3) {
        note("polygon: needs 3 vertices that are not on one line");
        return false;
    }
    if (!applyEdit("place polygon", [&](Scene& s) {
            created = addPolygon(s, hull, &problem);
            return !created.isNull();
        })) {
        note("refused: " + problem);
        return false;
    }
    selection = {created};
    return true;
}

render::FrameInput Editor::frameInput() const {
    render::FrameInput in;
    in.scene = &doc.scene;
    in.world = sim.world();
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
