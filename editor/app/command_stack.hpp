#pragma once
/// \file command_stack.hpp
/// Undo and redo ("Command" pattern). Every change to the document goes
/// through apply(): it runs the edit on the scene and keeps only what
/// changed: each touched entity's components before and after (encoded
/// through the component table), the slot table when entities came or went
/// (so undo brings back the very same handles), and the world settings,
/// view and solver state when they changed. The registry tells apply() which
/// entities the edit reaches (RegistryObserver), so an edit costs what it
/// touches, not the size of the level: moving one body of a 20,000-body
/// level encodes that body and copies nothing else.
///
/// Coalescing: edits that carry the same non-zero `mergeKey` while the top
/// command is still open (a drag in progress, a slider being dragged) fold
/// into one command, so one drag is one undo step. closeMerge() ends it
/// (mouse up, widget deactivated).

#include "stepwise/scene.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <utility>
#include <string>
#include <vector>

namespace stepwise::editor {

class CommandStack {
public:
    /// Oldest commands are dropped past this many, or past `budgetBytes` of
    /// recorded changes (memory bound).
    explicit CommandStack(std::size_t capacity = 10000, std::size_t budgetBytes = std::size_t(64) << 20)
        : capacity_(capacity), budgetBytes_(budgetBytes) {}

    /// Runs `edit` on `scene` as one undoable step named `label`. Returns
    /// false (and records nothing) when the edit changed nothing or threw
    /// away its change by returning false.
    bool apply(Scene& scene, std::string label, const std::function<bool(Scene&)>& edit, std::uint64_t mergeKey = 0);

    /// Ends coalescing: the next apply() starts a new command.
    void closeMerge() { open_ = false; }

    bool canUndo() const { return cursor_ > 0; }
    bool canRedo() const { return cursor_ < commands_.size(); }
    /// Whether the command the next undo (false) or redo (true) applies
    /// finds the scene's entity table as it left it: a run that added or
    /// removed entities since (an emitter's copies, a broken joint) leaves
    /// an add or delete that cannot be undone exactly; every other command
    /// can.
    bool entitiesAsLeft(const Scene& scene, bool redo) const;
    /// Restores the scene before the last command. Returns its label ("" if none).
    std::string undo(Scene& scene);
    std::string redo(Scene& scene);

    /// Labels, oldest first, and how many of them are applied (for a history list).
    std::vector<std::string> labels() const;
    std::size_t cursor() const { return cursor_; }
    std::size_t size() const { return commands_.size(); }

    /// Drops every command after position `n` and makes `n` the cursor
    /// without touching the scene (reset discards the edits made while the
    /// simulation was paused).
    void truncate(std::size_t n);
    void clear();

    /// What the last successful apply(), undo() or redo() changed, that
    /// edit alone (merged into the command before it or not): each entity
    /// it changed, with the component-table indices of its changed
    /// components as bits (created and destroyed ones included), the
    /// entities it created (in scene order) and destroyed, and whether
    /// anything else changed (the world settings, the solver state, the
    /// order of the entities that stayed). The simulation applies to its
    /// World in place an edit that moved, turned, re-massed or reshaped
    /// bodies, or added or deleted some.
    struct EditSummary {
        std::vector<std::pair<Entity, std::uint64_t>> entities;
        std::vector<Entity> created, destroyed;
        bool beyondComponents = false;
    };
    const EditSummary& lastEdit() const { return lastEdit_; }

    /// Bumped by every apply/undo/redo: lets views know the scene changed.
    std::uint64_t revision() const { return revision_; }
    /// Position of the cursor counted from the first command ever applied
    /// (commands dropped for capacity included): identifies a saved state.
    std::uint64_t absoluteCursor() const { return dropped_ + cursor_; }
    /// Heap bytes the recorded commands hold (labels and changes).
    std::size_t bytes() const { return bytes_; }

    /// A value before and after an edit, kept on the heap: most commands
    /// change none of these, and then one costs a pointer (held inline,
    /// the slot table, world settings and solver state on both sides made
    /// every one-body command nearly a kilobyte).
    template <class T>
    class Change {
    public:
        explicit operator bool() const { return bool(pair_); }
        const std::pair<T, T>* operator->() const { return pair_.get(); }
        std::pair<T, T>* operator->() { return pair_.get(); }
        void emplace(T before, T after) { pair_ = std::make_unique<std::pair<T, T>>(std::move(before), std::move(after)); }
        std::size_t heapBytes() const { return pair_ ? sizeof(std::pair<T, T>) : 0; }

    private:
        std::unique_ptr<std::pair<T, T>> pair_;
    };

    /// What one command changed; each pair is (before, after).
    struct Delta {
        struct EntityChange {
            Entity entity;
            std::string before, after;  ///< encoded components; "" = not alive on that side
        };
        std::vector<EntityChange> entities;
        Change<Registry::Slots> slots;
        Change<WorldSettings> world;
        Change<std::optional<View>> view;
        Change<std::optional<SolverState>> solver;
        Change<int> version;
        std::size_t bytes() const;
    };
    /// Turns the scene on one side of `delta` into the other (forward:
    /// before -> after); `summary`, when given, gets what that changed.
    static void apply(Scene& scene, const Delta& delta, bool forward, EditSummary* summary = nullptr);

private:
    struct Command {
        std::string label;
        Delta delta;
        std::uint64_t mergeKey = 0;
        std::size_t bytes() const { return label.capacity() + delta.bytes(); }
    };
    void dropOldest();
    std::vector<Command> commands_;
    std::size_t cursor_ = 0;
    std::size_t capacity_;
    std::size_t budgetBytes_;
    std::size_t bytes_ = 0;
    bool open_ = false;
    std::uint64_t revision_ = 0;
    std::uint64_t dropped_ = 0;
    EditSummary lastEdit_;
};

} // namespace stepwise::editor
