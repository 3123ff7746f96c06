#pragma once
/// \file script_actions.hpp
/// The script's actions (play, step, tool, select, ...): one table of what
/// each is called, which arguments it takes and what it does to the editor.
/// The parser (script.cpp) checks arguments against it, the headless runner
/// calls runScriptAction. Adding an action is adding one entry.
///
/// What an action needs beyond the editor model (the panels, the pixels,
/// drawing a frame) comes through ScriptHost, which the runner implements.

#include "app/script.hpp"

#include "stepwise/result.hpp"

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace stepwise::editor {

class Editor;

/// The program running a script: what the editor model does not own.
class ScriptHost {
public:
    virtual ~ScriptHost() = default;
    /// Draws one frame (events queued so far are handled in it).
    virtual void frame() = 0;
    /// Shows or hides a panel by its script name; false when there is no such panel.
    virtual bool showWindow(const std::string& name, bool on) = 0;
    /// Selects a tab of the Debug panel by its script name; false when there is no such tab.
    virtual bool showDebugTab(const std::string& name) = 0;
    /// Writes the whole window as a PNG.
    virtual Result<void> screenshot(const std::string& path) = 0;
    /// Prints a failure ("stepwise: error: ..." on stderr for the CLI).
    virtual void reportError(const std::string& message) = 0;
};

/// One action being run: the editor, the host and where failures go.
class ScriptActionRun {
public:
    ScriptActionRun(Editor& editor, ScriptHost& host, const ScriptCommand& command, std::string scriptName);

    Editor& ed;
    ScriptHost& host;
    const ScriptCommand& c;

    /// Reports "SCRIPT:LINE: what" and marks the run failed.
    void failLine(const std::string& what);
    /// failLine(what), followed by the text of the error dialog the action
    /// opened, if it opened one.
    void failed(const char* what);
    bool ok() const { return ok_; }
    /// The error dialog's text before the action ran.
    const std::string& modalBefore() const { return modalBefore_; }

private:
    std::string scriptName_;
    std::string modalBefore_;
    bool ok_ = true;
};

struct ScriptAction {
    std::string name;     ///< the script's verb
    std::size_t minArgs = 0, maxArgs = 0;
    std::string usage;    ///< shown after "expected: " when the arguments do not fit
    /// Optional: checks and converts the arguments at parse time (into
    /// c.count or c.number); the error is the line's message.
    Result<void> (*parse)(ScriptCommand& c) = nullptr;
    void (*run)(ScriptActionRun& run) = nullptr;
    /// False for an action that draws its own frames (screenshot): the
    /// runner then neither checks the error dialog nor draws one after it.
    bool settles = true;
};

/// Every action, in the order the parser's "unknown command" message lists them.
const std::vector<ScriptAction>& scriptActions();
/// The action named `name`, or nullptr.
const ScriptAction* findScriptAction(std::string_view name);

/// Runs one Action command: the action, then (unless it draws its own
/// frames) a failure if it opened an error dialog, and a frame. Returns
/// false when the script must stop (the failure has been reported).
bool runScriptAction(Editor& editor, ScriptHost& host, const ScriptCommand& command, const std::string& scriptName);

} // namespace stepwise::editor
