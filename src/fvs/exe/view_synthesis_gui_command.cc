// colmap view_synthesis_gui [--workspace_path W] [--model_path weights.safetensors]
// The Qt "Render novel view" application (src/ui). Builds without Qt
// (-DFVS_WITH_GUI=OFF) keep the command, which then says so in one line.
#include <string>

#include "fvs/exe/command_registry.h"
#include "fvs/util/error.h"
#include "fvs/util/option_manager.h"

#ifdef FVS_WITH_GUI
#include <QApplication>
#include <QOpenGLContext>
#include <QString>
#include <cstdlib>

#include "ui/main_window.h"
#endif

namespace fvs {
namespace {

int RunViewSynthesisGui(int argc, char** argv) {
  std::string workspace_path;
  std::string model_path;
  std::string method = "ulr";
  OptionManager options(
      "view_synthesis_gui",
      "The 'Render novel view' application: a 3D view of the workspace, "
      "novel views rendered at the current viewpoint, camera paths.");
  options.AddDefault("workspace_path", &workspace_path,
                     "workspace to open (view_synthesis_prepare output or a COLMAP dense "
                     "workspace)");
  options.AddDefault("model_path", &model_path, "network weights for the fvs methods");
  options.AddDefault("method", &method, "initial method (ulr, nearest, fvs, ...)");
  if (!options.Parse(argc, argv)) return 0;
#ifdef FVS_WITH_GUI
  // Without a display Qt's xcb platform aborts: say so in one line instead.
  const char* platform = std::getenv("QT_QPA_PLATFORM");
  const std::string platform_name = platform ? platform : "";
  if ((platform_name.empty() || platform_name == "xcb") && !std::getenv("DISPLAY") &&
      !std::getenv("WAYLAND_DISPLAY")) {
    throw Error("colmap view_synthesis_gui",
                "no display (DISPLAY is not set); run it on a desktop, over ssh -X, or "
                "under xvfb-run");
  }
  ui::SetDefaultSurfaceFormat();
  // Qt keeps references to argc/argv: give it its own copy of the program name only (our
  // options are parsed above).
  static int qt_argc = 1;
  static char* qt_argv[] = {argv[0], nullptr};
  QApplication app(qt_argc, qt_argv);
  {
    QOpenGLContext context;
    Require(context.create(), "colmap view_synthesis_gui",
            "cannot create an OpenGL 3.3 context on the Qt platform '" +
                QApplication::platformName().toStdString() +
                "' (Qt's offscreen platform has none; use X11/Wayland or xvfb-run)");
  }
  ui::MainWindow window;
  window.SetInitialSettings(QString::fromStdString(method),
                            QString::fromStdString(model_path));
  window.show();
  if (!workspace_path.empty()) {
    const QString error = window.OpenWorkspace(QString::fromStdString(workspace_path));
    if (!error.isEmpty()) window.ShowError(error);
  }
  return app.exec();
#else
  throw Error(
      "colmap view_synthesis_gui",
      "this build has no GUI (configure with -DFVS_WITH_GUI=ON and Qt5 installed)");
#endif
}

}  // namespace

FVS_REGISTER_COMMAND("view_synthesis_gui", "the Qt 'Render novel view' application",
                     RunViewSynthesisGui);

}  // namespace fvs
