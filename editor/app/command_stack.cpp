#include "app/command_stack.hpp"

namespace stepwise::editor {

bool CommandStack::apply(Scene& scene, std::string label, const std::function<bool(Scene&)>& edit,
                         std::uint64_t mergeKey) {
    const bool merging = open_ && mergeKey != 0 && cursor_ == commands_.size() && cursor_ > 0 &&
                         commands_[cursor_ - 1].mergeKey == mergeKey;
    if (merging) {
        // The command keeps its original "before"; only "after" moves on.
        if (!edit(scene)) return false;
        commands_[cursor_ - 1].after = scene;
        ++revision_;
        return true;
    }
    Scene before = scene;
    if (!edit(scene)) {
        scene = std::move(before);  // an edit that gave up must leave no trace
        return false;
    }
    commands_.resize(cursor_);  // a new edit forgets the redo branch
    commands_.push_back(Command{std::move(label), std::move(before), scene, mergeKey});
    if (commands_.size() > capacity_) {
        commands_.erase(commands_.begin());
        ++dropped_;
    }
    cursor_ = commands_.size();
    open_ = mergeKey != 0;
    ++revision_;
    return true;
}

std::string CommandStack::undo(Scene& scene) {
    open_ = false;
    if (!canUndo()) return {};
    --cursor_;
    scene = commands_[cursor_].before;
    ++revision_;
    return commands_[cursor_].label;
}

std::string CommandStack::redo(Scene& scene) {
    open_ = false;
    if (!canRedo()) return {};
    scene = commands_[cursor_].after;
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
    if (n < commands_.size()) commands_.resize(n);
    cursor_ = std::min(cursor_, commands_.size());
    open_ = false;
    ++revision_;
}

void CommandStack::clear() {
    commands_.clear();
    cursor_ = 0;
    open_ = false;
    ++revision_;
}

} // namespace stepwise::editor
