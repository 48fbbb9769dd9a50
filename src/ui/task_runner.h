// Long work (opening a workspace, rendering a view or a path) runs on a thread of its own
// so that the window never freezes. A task is a function run on that thread; it returns
// the continuation that shows its result, which runs later on the GUI thread. Cancel()
// abandons the running task at once (its continuation is dropped, the window is usable
// again); the work itself stops where it next checks `cancelled` (between frames of a
// path, or in every ParallelFor of a render run under a CancelScope on it) or runs to
// its end in the background.
#pragma once

#include <QObject>
#include <QString>
#include <atomic>
#include <functional>
#include <memory>
#include <thread>
#include <vector>

namespace fvs::ui {

class TaskRunner : public QObject {
  Q_OBJECT

 public:
  struct Control {
    std::atomic<bool> cancelled{false};
    std::atomic<bool> finished{false};
  };
  using Continuation = std::function<void()>;
  // Reports progress (done of total) from the task's thread.
  using ProgressFn = std::function<void(int done, int total, const QString& text)>;
  using Work = std::function<Continuation(const Control& control, const ProgressFn&)>;
  // Shows an error of the task (an exception's message), on the GUI thread.
  using ErrorFn = std::function<void(const QString& message)>;

  explicit TaskRunner(QObject* parent = nullptr);
  // Cancels whatever runs and waits for the threads (a render in flight finishes first).
  ~TaskRunner() override;

  // Starts `work` unless a task is running (returns false then).
  bool Start(const QString& label, Work work, ErrorFn on_error);
  void Cancel();
  bool busy() const { return current_ != nullptr; }
  const QString& label() const { return label_; }

 Q_SIGNALS:
  void started(const QString& label);
  // done/total of the running task; total 0 means "busy, length unknown".
  void progress(int done, int total, const QString& text);
  // The running task ended (finished, failed or cancelled); the window is free again.
  void stopped(bool cancelled);

 private:
  void JoinFinished();

  std::shared_ptr<Control> current_;
  QString label_;
  std::vector<std::pair<std::shared_ptr<Control>, std::thread>> threads_;
};

}  // namespace fvs::ui
