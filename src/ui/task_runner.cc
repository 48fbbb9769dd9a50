#include "ui/task_runner.h"

#include <QMetaObject>
#include <exception>

namespace fvs::ui {

TaskRunner::TaskRunner(QObject* parent) : QObject(parent) {}

TaskRunner::~TaskRunner() {
  if (current_) current_->cancelled = true;
  for (auto& [control, thread] : threads_) {
    control->cancelled = true;
    if (thread.joinable()) thread.join();
  }
}

void TaskRunner::JoinFinished() {
  for (auto it = threads_.begin(); it != threads_.end();) {
    if (it->first->finished) {
      if (it->second.joinable()) it->second.join();
      it = threads_.erase(it);
    } else {
      ++it;
    }
  }
}

bool TaskRunner::Start(const QString& label, Work work, ErrorFn on_error) {
  if (current_) return false;
  JoinFinished();
  auto control = std::make_shared<Control>();
  current_ = control;
  label_ = label;
  Q_EMIT started(label);
  Q_EMIT progress(0, 0, label);

  // Everything the thread posts back runs on the GUI thread and first checks that its
  // task is still the current one: a cancelled task's results are dropped.
  auto post = [this, control](std::function<void()> fn) {
    QMetaObject::invokeMethod(
        this,
        [this, control, fn = std::move(fn)] {
          if (current_ == control && !control->cancelled) fn();
        },
        Qt::QueuedConnection);
  };
  ProgressFn report = [this, post](int done, int total, const QString& text) {
    post([this, done, total, text] { Q_EMIT progress(done, total, text); });
  };
  std::thread thread([this, control, post, report, work = std::move(work),
                      on_error = std::move(on_error)] {
    Continuation done;
    QString error;
    try {
      done = work(*control, report);
    } catch (const std::exception& e) {
      error = QString::fromStdString(e.what());
    } catch (...) {
      error = QStringLiteral("unknown error");
    }
    post([this, control, done, error, on_error] {
      current_.reset();
      if (!error.isEmpty()) {
        if (on_error) on_error(error);
      } else if (done) {
        done();
      }
      Q_EMIT stopped(false);
    });
    control->finished = true;
  });
  threads_.emplace_back(control, std::move(thread));
  return true;
}

void TaskRunner::Cancel() {
  if (!current_) return;
  current_->cancelled = true;
  current_.reset();
  Q_EMIT stopped(true);
}

}  // namespace fvs::ui
