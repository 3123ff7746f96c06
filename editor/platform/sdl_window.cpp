// The SDL2 platform loop of `stepwise edit` (no --script/--screenshot).

#include "platform/sdl_window.hpp"

#include "app/events.hpp"
#include "app/scene_edit.hpp"
#include "ui/session.hpp"

#include <SDL.h>

#include <algorithm>
#include <chrono>
#include <cstring>

namespace stepwise::platform {

using editor::benchScene;
using ui::EditOptions;
using ui::FrameTimes;
using ui::writeDebugState;
using editor::InputEvent;
using editor::Key;

namespace {

Key keyFromSdl(SDL_Keycode k) {
    if (k >= SDLK_a && k <= SDLK_z) return Key(std::uint16_t(Key::A) + std::uint16_t(k - SDLK_a));
    if (k >= SDLK_0 && k <= SDLK_9) return Key(std::uint16_t(Key::Num0) + std::uint16_t(k - SDLK_0));
    switch (k) {
    case SDLK_SPACE: return Key::Space;
    case SDLK_LEFT: return Key::Left;
    case SDLK_RIGHT: return Key::Right;
    case SDLK_UP: return Key::Up;
    case SDLK_DOWN: return Key::Down;
    case SDLK_DELETE: return Key::Delete;
    case SDLK_BACKSPACE: return Key::Backspace;
    case SDLK_ESCAPE: return Key::Escape;
    case SDLK_RETURN:
    case SDLK_KP_ENTER: return Key::Enter;
    case SDLK_TAB: return Key::Tab;
    case SDLK_HOME: return Key::Home;
    case SDLK_END: return Key::End;
    case SDLK_PAGEUP: return Key::PageUp;
    case SDLK_PAGEDOWN: return Key::PageDown;
    case SDLK_F1: return Key::F1;
    case SDLK_F2: return Key::F2;
    case SDLK_F3: return Key::F3;
    case SDLK_F4: return Key::F4;
    case SDLK_F5: return Key::F5;
    default: return Key::None;
    }
}

std::uint8_t modsFromSdl(Uint16 m) {
    std::uint8_t out = 0;
    if (m & KMOD_CTRL) out |= editor::kModCtrl;
    if (m & KMOD_SHIFT) out |= editor::kModShift;
    if (m & KMOD_ALT) out |= editor::kModAlt;
    return out;
}

} // namespace

Result<void> runWindow(const EditOptions& o, int width, int height) {
    if (SDL_Init(SDL_INIT_VIDEO | SDL_INIT_TIMER) != 0)
        return Error{std::string("cannot start SDL video (is there a display? use --script/--screenshot for headless "
                                 "runs): ") + SDL_GetError()};
    // With no display, Debian's SDL 2.26 does not fail: it falls back to its
    // invisible "offscreen" driver, and the editor would run a window nobody
    // can see until it is killed. Such a driver is honoured only when asked
    // for by name (SDL_VIDEODRIVER).
    const char* driver = SDL_GetCurrentVideoDriver();
    if (driver && (!std::strcmp(driver, "offscreen") || !std::strcmp(driver, "dummy")) && !SDL_getenv("SDL_VIDEODRIVER")) {
        SDL_Quit();
        return Error{std::string("cannot start SDL video (is there a display? use --script/--screenshot for headless "
                                 "runs): SDL found no display, only its \"") + driver + "\" driver"};
    }
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_PROFILE_MASK, SDL_GL_CONTEXT_PROFILE_CORE);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MAJOR_VERSION, 3);
    SDL_GL_SetAttribute(SDL_GL_CONTEXT_MINOR_VERSION, 3);
    SDL_GL_SetAttribute(SDL_GL_DOUBLEBUFFER, 1);
    SDL_GL_SetAttribute(SDL_GL_DEPTH_SIZE, 0);
    // The window fits the screen it opens on: a 1280x800 window on a
    // 720-pixel screen opened with its menu bar above the top edge.
    SDL_Rect usable{};
    const bool bounded = SDL_GetDisplayUsableBounds(0, &usable) == 0 && usable.w > 0 && usable.h > 0;
    if (bounded) {
        width = std::min(width, usable.w);
        height = std::min(height, usable.h);
    }
    SDL_Window* window = SDL_CreateWindow("Stepwise", SDL_WINDOWPOS_CENTERED, SDL_WINDOWPOS_CENTERED, width, height,
                                          SDL_WINDOW_OPENGL | SDL_WINDOW_RESIZABLE);
    if (!window) {
        Error e{std::string("cannot open a window: ") + SDL_GetError()};
        SDL_Quit();
        return e;
    }
    // Its frame (title bar) is known only now: the whole, frame included, fits.
    int top = 0, left = 0, bottom = 0, right = 0;
    if (bounded && SDL_GetWindowBordersSize(window, &top, &left, &bottom, &right) == 0 &&
        (height + top + bottom > usable.h || width + left + right > usable.w)) {
        width = std::min(width, usable.w - left - right);
        height = std::min(height, usable.h - top - bottom);
        SDL_SetWindowSize(window, width, height);
        SDL_SetWindowPosition(window, usable.x + left, usable.y + top);
    }
    SDL_GLContext context = SDL_GL_CreateContext(window);
    if (!context) {
        Error e{std::string("cannot create an OpenGL 3.3 core context: ") + SDL_GetError()};
        SDL_DestroyWindow(window);
        SDL_Quit();
        return e;
    }
    SDL_GL_MakeCurrent(window, context);
    SDL_GL_SetSwapInterval(o.noVsync || o.benchFrames > 0 ? 0 : 1);
    float dpi = 96.0f;
    if (SDL_GetDisplayDPI(0, nullptr, &dpi, nullptr) != 0 || !(dpi > 0)) dpi = 96.0f;
    ui::SessionOptions so;
    so.fontSize = o.fontSize;
    so.builtinFont = o.builtinFont;
    so.dpiScale = std::clamp(dpi / 96.0f, 1.0f, 3.0f);
    if (!o.configDir.empty()) so.configDir = o.configDir;
    Result<void> outcome;
    {
        Result<std::unique_ptr<ui::Session>> created =
            ui::Session::create([](const char* n) { return SDL_GL_GetProcAddress(n); }, so);
        if (!created) {
            outcome = Error{created.error()};
        } else {
            ui::Session& session = **created;
            editor::Editor& ed = session.editor();
            if (o.benchBodies > 0) {
                ed.doc.reset(benchScene(o.benchBodies));
                ed.fitView();
            } else {
                (void)session.openAtStart(o.level);  // a bad level: the error modal shows the loader's message
            }
            if (!o.overlays.empty()) ed.overlays = render::parseOverlayList(o.overlays).value();
            SDL_StartTextInput();
            auto last = std::chrono::steady_clock::now();
            const auto start = last;
            std::uint64_t frameNo = 0;
            FrameTimes times;
            bool benchPlaying = false;
            // A frame is drawn, then shown from inside the next one (see
            // Session::frame), or before the loop idles.
            bool drawnNotShown = false;
            const auto presentPrevious = [&] {
                if (drawnNotShown) SDL_GL_SwapWindow(window);
                drawnNotShown = false;
            };
            while (!session.wantsQuit()) {
                SDL_Event ev;
                while (SDL_PollEvent(&ev)) {
                    InputEvent e;
                    switch (ev.type) {
                    case SDL_QUIT: ed.request(editor::PendingAction::Quit); break;
                    case SDL_KEYDOWN:
                    case SDL_KEYUP:
                        e.type = ev.type == SDL_KEYDOWN ? InputEvent::Type::KeyDown : InputEvent::Type::KeyUp;
                        e.key = keyFromSdl(ev.key.keysym.sym);
                        e.mods = modsFromSdl(ev.key.keysym.mod);
                        // Modifier keys themselves update the held modifiers.
                        session.queue(e);
                        break;
                    case SDL_TEXTINPUT:
                        e.type = InputEvent::Type::Text;
                        e.text = ev.text.text;
                        session.queue(e);
                        break;
                    case SDL_MOUSEMOTION:
                        e.type = InputEvent::Type::MouseMove;
                        e.x = ev.motion.x;
                        e.y = ev.motion.y;
                        session.queue(e);
                        break;
                    case SDL_MOUSEBUTTONDOWN:
                    case SDL_MOUSEBUTTONUP:
                        if (ev.button.button > 3) break;
                        e.type = ev.type == SDL_MOUSEBUTTONDOWN ? InputEvent::Type::MouseDown : InputEvent::Type::MouseUp;
                        e.button = ev.button.button == SDL_BUTTON_LEFT ? editor::MouseButton::Left
                                   : ev.button.button == SDL_BUTTON_RIGHT ? editor::MouseButton::Right
                                                                          : editor::MouseButton::Middle;
                        e.x = ev.button.x;
                        e.y = ev.button.y;
                        e.mods = modsFromSdl(Uint16(SDL_GetModState()));
                        session.queue(e);
                        break;
                    case SDL_MOUSEWHEEL: {
                        int mx = 0, my = 0;
                        SDL_GetMouseState(&mx, &my);
                        e.type = InputEvent::Type::Wheel;
                        e.wheel = ev.wheel.y;
                        e.x = mx;
                        e.y = my;
                        session.queue(e);
                        break;
                    }
                    default: break;
                    }
                }
                int w = width, h = height;
                SDL_GL_GetDrawableSize(window, &w, &h);
                const auto now = std::chrono::steady_clock::now();
                // Real time, clamped: a stall (window drag, debugger) must
                // not turn into a burst of steps.
                const double seconds = std::clamp(std::chrono::duration<double>(now - last).count(), 0.0, 0.1);
                if (o.benchFrames > 0 && frameNo > 0)
                    times.add(1e3 * std::chrono::duration<double>(now - last).count(), session.ui().lastFrame);
                last = now;
                if (o.benchFrames > 0 && !benchPlaying) {
                    ed.togglePlay();
                    benchPlaying = true;
                }
                session.frame(w, h, seconds, presentPrevious);
                drawnNotShown = true;
                ++frameNo;
                ed.tickAutosave(std::chrono::duration<double>(now - start).count());
                if (!o.debugState.empty() && frameNo % 10 == 0) writeDebugState(o.debugState, session, frameNo);
                if (o.benchFrames > 0 && int(times.ms.size()) >= o.benchFrames) break;
                // While a modal waits on the user, nothing moves: idle a little.
                if (!session.hasQueuedEvents() && ed.sim.state() != editor::SimState::Playing && o.benchFrames == 0) {
                    presentPrevious();  // idle: show the last frame now, not after the wait
                    SDL_WaitEventTimeout(nullptr, 15);
                }
            }
            if (o.benchFrames > 0) times.report("SDL window, swap included", ed.doc.scene.registry.size());
            session.saveSettings();
            if (!ed.dirty()) ed.discardRecovery();
        }
    }
    SDL_GL_DeleteContext(context);
    SDL_DestroyWindow(window);
    SDL_Quit();
    return outcome;
}

} // namespace stepwise::platform
