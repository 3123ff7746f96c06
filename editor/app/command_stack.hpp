#pragma once
/// \file command_stack.hpp
/// Undo and redo ("Command" pattern, with snapshots). Every change to the
/// document goes through apply(): it copies the scene, runs the edit, and
/// keeps the before and after copies. Snapshots are the simplest commands
/// that are always exactly invertible (undo restores the same bytes); a
/// Registry is deep-copyable, and at editor scene sizes (thousands of
/// entities, a few hundred KiB) a copy costs well under a millisecond.
///
/// Coalescing: edits that carry the same non-zero `mergeKey` while the top
/// command is still open (a drag in progress, a slider being dragged) fold
/// into one command, so one drag is one undo step. closeMerge() ends it
/// (mouse up, widget deactivated).

#include "stepwise/scene.hpp"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace stepwise::editor {

class CommandStack {
public:
    /// Oldest commands are dropped past this many (memory bound).
    explicit CommandStack(std::size_t capacity = 256) : capacity_(capacity) {}

    /// Runs `edit` on `scene` as one undoable step named `label`. Returns
    /// false (and records nothing) when the edit changed nothing or threw
    /// away its change by returning false.
    bool apply(Scene& scene, std::string label, const std::function<bool(Scene&)>& edit, std::uint64_t mergeKey = 0);

    /// Ends coalescing: the next apply() starts a new command.
    void closeMerge() { open_ = false; }

    bool canUndo() const { return cursor_ > 0; }
    bool canRedo() const { return cursor_ < commands_.size(); }
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

    /// Bumped by every apply/undo/redo: lets views know the scene changed.
    std::uint64_t revision() const { return revision_; }
    /// Position of the cursor counted from the first command ever applied
    /// (commands dropped for capacity included): identifies a saved state.
    std::uint64_t absoluteCursor() const { return dropped_ + cursor_; }

private:
    struct Command {
        std::string label;
        Scene before, after;
        std::uint64_t mergeKey = 0;
    };
    std::vector<Command> commands_;
    std::size_t cursor_ = 0;
    std::size_t capacity_;
    bool open_ = false;
    std::uint64_t revision_ = 0;
    std::uint64_t dropped_ = 0;
};

} // namespace stepwise::editor
