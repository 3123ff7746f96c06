#include "app/command_stack.hpp"

#include "stepwise/component_table.hpp"
#include "stepwise/components.hpp"

#include <algorithm>
#include <cstring>
#include <unordered_set>

namespace stepwise::editor {

namespace {

// An entity's components as bytes, driven by the component table: a marker
// (so an alive entity with no components is not ""), then per component its
// table index and its fields in table order. Numbers are copied bit for bit,
// so decoding gives back the same doubles.
template <class T>
void put(std::string& out, const T& v) {
    out.append(reinterpret_cast<const char*>(&v), sizeof v);
}
template <class T>
T take(const std::string& in, std::size_t& at) {
    T v;
    std::memcpy(&v, in.data() + at, sizeof v);
    at += sizeof v;
    return v;
}

constexpr char kAlive = 'E';

template <class T>
void putOptional(std::string& out, const void* field) {
    const auto& o = *static_cast<const std::optional<T>*>(field);
    put(out, std::uint8_t(o.has_value()));
    if (o) put(out, *o);
}
template <class T>
void takeOptional(const std::string& in, std::size_t& at, void* field) {
    auto& o = *static_cast<std::optional<T>*>(field);
    o.reset();
    if (take<std::uint8_t>(in, at)) o = take<T>(in, at);
}

void putShapes(std::string& out, const void* field) {
    const auto& list = *static_cast<const std::vector<CompoundShape>*>(field);
    put(out, std::uint32_t(list.size()));
    for (const CompoundShape& s : list) {
        put(out, s.kind);
        put(out, s.center);
        put(out, s.radius);
        put(out, s.width);
        put(out, s.height);
        put(out, s.angle);
        put(out, std::uint32_t(s.vertices.size()));
        for (const Vec2 p : s.vertices) put(out, p);
        put(out, s.a);
        put(out, s.b);
        putOptional<double>(out, &s.density);
        putOptional<double>(out, &s.friction);
        putOptional<double>(out, &s.restitution);
        putOptional<bool>(out, &s.sensor);
        putOptional<Filter>(out, &s.filter);
    }
}

void takeShapes(const std::string& in, std::size_t& at, void* field) {
    auto& list = *static_cast<std::vector<CompoundShape>*>(field);
    list.resize(take<std::uint32_t>(in, at));
    for (CompoundShape& s : list) {
        s.kind = take<CompoundShape::Kind>(in, at);
        s.center = take<Vec2>(in, at);
        s.radius = take<double>(in, at);
        s.width = take<double>(in, at);
        s.height = take<double>(in, at);
        s.angle = take<double>(in, at);
        s.vertices.resize(take<std::uint32_t>(in, at));
        for (Vec2& p : s.vertices) p = take<Vec2>(in, at);
        s.a = take<Vec2>(in, at);
        s.b = take<Vec2>(in, at);
        takeOptional<double>(in, at, &s.density);
        takeOptional<double>(in, at, &s.friction);
        takeOptional<double>(in, at, &s.restitution);
        takeOptional<bool>(in, at, &s.sensor);
        takeOptional<Filter>(in, at, &s.filter);
    }
}

/// Appends component `c` of the table (at `component`) to `out`.
void encodeComponent(std::string& out, std::size_t c, const void* component) {
    const std::span<const ComponentInfo> table = componentTable();
    put(out, std::uint8_t(c));
    for (const FieldInfo& f : table[c].fields) {
        const void* field = f.address(const_cast<void*>(component));
        switch (f.kind) {
        case FieldKind::Number: put(out, *static_cast<const double*>(field)); break;
        case FieldKind::Integer: put(out, *static_cast<const int*>(field)); break;
        case FieldKind::Bits: put(out, *static_cast<const std::uint32_t*>(field)); break;
        case FieldKind::VectorList: {
            const auto& list = *static_cast<const std::vector<Vec2>*>(field);
            put(out, std::uint32_t(list.size()));
            for (const Vec2 p : list) put(out, p);
            break;
        }
        case FieldKind::ShapeList: putShapes(out, field); break;
        case FieldKind::IntegerList: {
            const auto& list = *static_cast<const std::vector<int>*>(field);
            put(out, std::uint32_t(list.size()));
            for (const int n : list) put(out, n);
            break;
        }
        case FieldKind::OptionalNumber: putOptional<double>(out, field); break;
        case FieldKind::Vector: put(out, *static_cast<const Vec2*>(field)); break;
        case FieldKind::OptionalVector: putOptional<Vec2>(out, field); break;
        case FieldKind::Color: put(out, *static_cast<const Rgb*>(field)); break;
        case FieldKind::Bool: put(out, std::uint8_t(*static_cast<const bool*>(field))); break;
        // A handle is stored as it is: undo and redo act on the same
        // registry, where it stays valid (or is detected as stale).
        case FieldKind::EntityRef: put(out, *static_cast<const Entity*>(field)); break;
        case FieldKind::String: {
            const auto& text = *static_cast<const std::string*>(field);
            put(out, std::uint32_t(text.size()));
            out += text;
            break;
        }
        }
    }
}

/// Where each component starts in an encoding: (table index, offset).
using ComponentStarts = std::vector<std::pair<std::uint8_t, std::uint32_t>>;

std::string encodeEntity(const Registry& reg, Entity e, ComponentStarts* starts = nullptr) {
    if (starts) starts->clear();
    if (!reg.alive(e)) return {};
    std::string out(1, kAlive);
    const std::span<const ComponentInfo> table = componentTable();
    for (std::size_t c = 0; c < table.size(); ++c)
        if (const void* component = table[c].getConst(reg, e)) {
            if (starts) starts->emplace_back(std::uint8_t(c), std::uint32_t(out.size()));
            encodeComponent(out, c, component);
        }
    return out;
}

/// The table indices of the components in which two encodings of one
/// entity differ (present on one side only included), as bits.
std::uint64_t changedComponents(const std::string& before, const ComponentStarts& was, const std::string& after,
                                const ComponentStarts& now) {
    // A component's bytes run from its start to the next one's, or the end.
    const auto bytesOf = [](const std::string& in, const ComponentStarts& starts, std::size_t k) {
        const std::size_t end = k + 1 < starts.size() ? starts[k + 1].second : in.size();
        return std::string_view(in).substr(starts[k].second, end - starts[k].second);
    };
    std::uint64_t mask = 0;
    std::size_t a = 0, b = 0;  // both lists are in table order
    while (a < was.size() || b < now.size()) {
        if (b == now.size() || (a < was.size() && was[a].first < now[b].first)) {
            mask |= std::uint64_t(1) << was[a++].first;
        } else if (a == was.size() || now[b].first < was[a].first) {
            mask |= std::uint64_t(1) << now[b++].first;
        } else {
            if (bytesOf(before, was, a) != bytesOf(after, now, b)) mask |= std::uint64_t(1) << was[a].first;
            ++a;
            ++b;
        }
    }
    return mask;
}


/// Gives alive entity `e` (with no components) the encoded components.
void decodeEntity(const std::string& in, Registry& reg, Entity e) {
    const std::span<const ComponentInfo> table = componentTable();
    std::size_t at = 1;
    while (at < in.size()) {
        const ComponentInfo& info = table[take<std::uint8_t>(in, at)];
        void* component = info.emplaceDefault(reg, e);
        for (const FieldInfo& f : info.fields) {
            void* field = f.address(component);
            switch (f.kind) {
            case FieldKind::Number: *static_cast<double*>(field) = take<double>(in, at); break;
            case FieldKind::Integer: *static_cast<int*>(field) = take<int>(in, at); break;
            case FieldKind::Bits: *static_cast<std::uint32_t*>(field) = take<std::uint32_t>(in, at); break;
            case FieldKind::VectorList: {
                auto& list = *static_cast<std::vector<Vec2>*>(field);
                list.resize(take<std::uint32_t>(in, at));
                for (Vec2& p : list) p = take<Vec2>(in, at);
                break;
            }
            case FieldKind::ShapeList: takeShapes(in, at, field); break;
            case FieldKind::IntegerList: {
                auto& list = *static_cast<std::vector<int>*>(field);
                list.resize(take<std::uint32_t>(in, at));
                for (int& n : list) n = take<int>(in, at);
                break;
            }
            case FieldKind::OptionalNumber: takeOptional<double>(in, at, field); break;
            case FieldKind::Vector: *static_cast<Vec2*>(field) = take<Vec2>(in, at); break;
            case FieldKind::OptionalVector: takeOptional<Vec2>(in, at, field); break;
            case FieldKind::Color: *static_cast<Rgb*>(field) = take<Rgb>(in, at); break;
            case FieldKind::Bool: *static_cast<bool*>(field) = take<std::uint8_t>(in, at) != 0; break;
            case FieldKind::EntityRef: *static_cast<Entity*>(field) = take<Entity>(in, at); break;
            case FieldKind::String: {
                const std::uint32_t n = take<std::uint32_t>(in, at);
                *static_cast<std::string*>(field) = in.substr(at, n);
                at += n;
                break;
            }
            }
        }
    }
}

void removeAllComponents(Registry& reg, Entity e) {
    if (!reg.alive(e)) return;
    for (const ComponentInfo& info : componentTable()) info.remove(reg, e);
}

template <class T>
void setIfChanged(CommandStack::Change<T>& slot, const T& before, const T& after) {
    if (!(before == after)) slot.emplace(before, after);
}

/// Merging: `later` follows `earlier`; the pair becomes (earlier's before,
/// later's after).
template <class T>
void compose(CommandStack::Change<T>& earlier, const CommandStack::Change<T>& later) {
    if (!later) return;
    if (earlier) earlier->second = later->second;
    else earlier.emplace(later->first, later->second);
}

/// Whether `e` is alive in a slot table taken earlier.
bool aliveIn(const Registry::Slots& slots, Entity e) {
    return e.index < slots.generations.size() && slots.alive[e.index] && slots.generations[e.index] == e.generation;
}

/// The entities that came and went between two slot tables; a change in
/// the order of those in both is beyond components.
void summarizeSlots(const Registry::Slots& before, const Registry::Slots& now, CommandStack::EditSummary& summary) {
    std::vector<Entity> stayedBefore, stayedNow;
    for (const Entity e : now.order) (aliveIn(before, e) ? stayedNow : summary.created).push_back(e);
    for (const Entity e : before.order) (aliveIn(now, e) ? stayedBefore : summary.destroyed).push_back(e);
    if (stayedBefore != stayedNow) summary.beyondComponents = true;
}

/// Keeps, while one edit runs, each entity's components as they were when
/// the edit first reached for them, and the slot table before its first
/// change: what the undo record needs, and all that is copied. An edit that
/// moves one body of a large level costs that body, not the level.
class EditJournal final : public RegistryObserver {
public:
    explicit EditJournal(Registry& registry) : registry_(registry) { registry_.setObserver(this); }
    ~EditJournal() { registry_.setObserver(nullptr); }
    EditJournal(const EditJournal&) = delete;
    EditJournal& operator=(const EditJournal&) = delete;

    void beforeEntityChange(const Registry& registry, Entity e) override {
        if (!seen_.insert(key(e)).second) return;
        // Created during this edit: it was not there before.
        const bool existed = !slots_ || aliveIn(*slots_, e);
        Touched& t = touched_.emplace_back();
        t.change.entity = e;
        if (existed) t.change.before = encodeEntity(registry, e, &t.before);
    }
    void beforeSlotsChange(const Registry& registry) override {
        if (!slots_) slots_ = registry.slots();
    }

    /// What the edit changed: the entities whose components differ now, and
    /// the slot table if it does; `summary` gets each changed entity's
    /// changed components. Ends the journal's watch.
    CommandStack::Delta finish(CommandStack::EditSummary& summary) {
        registry_.setObserver(nullptr);
        CommandStack::Delta d;
        summary.entities.clear();
        ComponentStarts after;
        const auto keep = [&](CommandStack::Delta::EntityChange&& c, const ComponentStarts& before) {
            summary.entities.emplace_back(c.entity, changedComponents(c.before, before, c.after, after));
            d.entities.push_back(std::move(c));
        };
        for (Touched& t : touched_) {
            t.change.after = encodeEntity(registry_, t.change.entity, &after);
            if (t.change.before != t.change.after) keep(std::move(t.change), t.before);
        }
        if (slots_) {
            Registry::Slots now = registry_.slots();
            // Created and never touched (no components): still a change.
            for (const Entity e : now.order)
                if (!aliveIn(*slots_, e) && !seen_.count(key(e))) {
                    std::string encoded = encodeEntity(registry_, e, &after);
                    keep({e, std::string(), std::move(encoded)}, {});
                }
            summarizeSlots(*slots_, now, summary);
            if (!(now == *slots_)) d.slots.emplace(std::move(*slots_), std::move(now));
        }
        d.entities.shrink_to_fit();
        return d;
    }

private:
    static std::uint64_t key(Entity e) { return (std::uint64_t(e.index) << 32) | e.generation; }
    Registry& registry_;
    struct Touched {
        CommandStack::Delta::EntityChange change;  ///< `before` filled now, `after` by finish()
        ComponentStarts before;
    };
    std::unordered_set<std::uint64_t> seen_;
    std::vector<Touched> touched_;
    std::optional<Registry::Slots> slots_;
};

} // namespace

std::size_t CommandStack::Delta::bytes() const {
    std::size_t n = sizeof(Delta) + entities.capacity() * sizeof(EntityChange);
    for (const EntityChange& c : entities) {
        // Short strings live inside the std::string itself (SSO).
        if (c.before.capacity() > 15) n += c.before.capacity() + 1;
        if (c.after.capacity() > 15) n += c.after.capacity() + 1;
    }
    n += slots.heapBytes() + world.heapBytes() + view.heapBytes() + solver.heapBytes() + version.heapBytes();
    if (slots) n += slots->first.bytes() + slots->second.bytes();
    if (solver)
        for (const std::optional<SolverState>* s : {&solver->first, &solver->second})
            if (*s) n += (*s)->contacts.capacity() * sizeof(ContactImpulse) + (*s)->joints.capacity() * sizeof(JointImpulse);
    return n;
}

void CommandStack::apply(Scene& scene, const Delta& d, bool forward, EditSummary* summary) {
    Registry& reg = scene.registry;
    // What each entity held before, to tell which components changed.
    std::vector<std::pair<std::string, ComponentStarts>> was;
    if (summary) {
        *summary = EditSummary{};
        was.resize(d.entities.size());
        for (std::size_t k = 0; k < d.entities.size(); ++k)
            was[k].first = encodeEntity(reg, d.entities[k].entity, &was[k].second);
    }
    for (const Delta::EntityChange& c : d.entities) removeAllComponents(reg, c.entity);
    if (d.slots) {
        const Registry::Slots& from = forward ? d.slots->first : d.slots->second;
        const Registry::Slots& to = forward ? d.slots->second : d.slots->first;
        if (summary) summarizeSlots(from, to, *summary);
        reg.setSlots(to);
    }
    ComponentStarts now;
    for (std::size_t k = 0; k < d.entities.size(); ++k) {
        const Delta::EntityChange& c = d.entities[k];
        const std::string& target = forward ? c.after : c.before;
        if (!target.empty()) decodeEntity(target, reg, c.entity);
        if (summary) {
            const std::string encoded = encodeEntity(reg, c.entity, &now);
            summary->entities.emplace_back(c.entity, changedComponents(was[k].first, was[k].second, encoded, now));
        }
    }
    if (summary) summary->beyondComponents = summary->beyondComponents || d.world || d.solver || d.version;
    if (d.world) scene.world = forward ? d.world->second : d.world->first;
    if (d.view) scene.view = forward ? d.view->second : d.view->first;
    if (d.solver) scene.solverState = forward ? d.solver->second : d.solver->first;
    if (d.version) scene.version = forward ? d.version->second : d.version->first;
}

bool CommandStack::apply(Scene& scene, std::string label, const std::function<bool(Scene&)>& edit,
                         std::uint64_t mergeKey) {
    const bool merging = open_ && mergeKey != 0 && cursor_ == commands_.size() && cursor_ > 0 &&
                         commands_[cursor_ - 1].mergeKey == mergeKey;
    // The scene's small parts are copied whole; its entities only as the
    // edit reaches them (EditJournal).
    const WorldSettings worldBefore = scene.world;
    const std::optional<View> viewBefore = scene.view;
    const std::optional<SolverState> solverBefore = scene.solverState;
    const int versionBefore = scene.version;
    EditJournal journal(scene.registry);
    const bool kept = edit(scene);
    EditSummary summary;
    Delta change = journal.finish(summary);
    setIfChanged(change.world, worldBefore, scene.world);
    setIfChanged(change.view, viewBefore, scene.view);
    setIfChanged(change.solver, solverBefore, scene.solverState);
    setIfChanged(change.version, versionBefore, scene.version);
    if (!kept) {
        apply(scene, change, false);  // an edit that gave up must leave no trace
        return false;
    }
    summary.beyondComponents = summary.beyondComponents || change.world || change.solver || change.version;
    lastEdit_ = std::move(summary);
    if (merging) {
        // The command keeps its original "before"; only "after" moves on.
        Command& top = commands_[cursor_ - 1];
        bytes_ -= top.bytes();
        Delta& d = top.delta;
        for (Delta::EntityChange& c : change.entities) {
            const auto it = std::find_if(d.entities.begin(), d.entities.end(),
                                         [&](const Delta::EntityChange& o) { return o.entity == c.entity; });
            if (it != d.entities.end()) it->after = std::move(c.after);
            else d.entities.push_back(std::move(c));
        }
        compose(d.slots, change.slots);
        compose(d.world, change.world);
        compose(d.view, change.view);
        compose(d.solver, change.solver);
        compose(d.version, change.version);
        bytes_ += top.bytes();
        ++revision_;
        return true;
    }
    for (std::size_t i = cursor_; i < commands_.size(); ++i) bytes_ -= commands_[i].bytes();
    commands_.resize(cursor_);  // a new edit forgets the redo branch
    commands_.push_back(Command{std::move(label), std::move(change), mergeKey});
    bytes_ += commands_.back().bytes();
    while (commands_.size() > capacity_ || (commands_.size() > 1 && bytes_ > budgetBytes_)) dropOldest();
    cursor_ = commands_.size();
    open_ = mergeKey != 0;
    ++revision_;
    return true;
}

void CommandStack::dropOldest() {
    bytes_ -= commands_.front().bytes();
    commands_.erase(commands_.begin());
    ++dropped_;
}

std::string CommandStack::undo(Scene& scene) {
    open_ = false;
    if (!canUndo()) return {};
    --cursor_;
    apply(scene, commands_[cursor_].delta, false, &lastEdit_);
    ++revision_;
    return commands_[cursor_].label;
}

bool CommandStack::entitiesAsLeft(const Scene& scene, bool redo) const {
    if (redo ? !canRedo() : !canUndo()) return true;
    const Delta& d = commands_[redo ? cursor_ : cursor_ - 1].delta;
    return !d.slots || scene.registry.hasSlots(redo ? d.slots->first : d.slots->second);
}

std::string CommandStack::redo(Scene& scene) {
    open_ = false;
    if (!canRedo()) return {};
    apply(scene, commands_[cursor_].delta, true, &lastEdit_);
    ++cursor_;
    ++revision_;
    return commands_[cursor_ - 1].label;
}

std::vector<std::string> CommandStack::labels() const {
    std::vector<std::string> out;
    out.reserve(commands_.size());
    for (const Command& c : commands_) out.push_back(c.label);
    return out;
}

void CommandStack::truncate(std::size_t n) {
    if (n < commands_.size()) {
        for (std::size_t i = n; i < commands_.size(); ++i) bytes_ -= commands_[i].bytes();
        commands_.resize(n);
    }
    cursor_ = std::min(cursor_, commands_.size());
    open_ = false;
    ++revision_;
}

void CommandStack::clear() {
    commands_.clear();
    bytes_ = 0;
    cursor_ = 0;
    open_ = false;
    ++revision_;
}

} // namespace stepwise::editor
