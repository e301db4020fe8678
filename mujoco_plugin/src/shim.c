// The C side of the plugin: the FMI logger (a C-variadic callback, which stable Rust cannot
// define) and the compile-time checks of src/layout.rs against MuJoCo's headers.
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>

#include <mujoco/mujoco.h>

#include "layout_checks.h"

// Defined in Rust (src/fmu.rs): receives the formatted message.
void actuator_fmus_mujoco_log(void* environment, int status, const char* category,
                              const char* message);

// fmi2CallbackLogger: formats the FMU's message (it is a printf format) and hands it to Rust.
void actuator_fmus_mujoco_fmi2_logger(void* environment, const char* instance_name, int status,
                                      const char* category, const char* message, ...) {
  (void)instance_name;
  char text[2048];
  va_list args;
  va_start(args, message);
  vsnprintf(text, sizeof text, message ? message : "", args);
  va_end(args);
  actuator_fmus_mujoco_log(environment, status, category ? category : "", text);
}

// MuJoCo's error and warning, with the message as an argument (never as the format). Called from
// Rust frames that hold nothing to drop: a host's error handler may unwind or longjmp through them.
void actuator_fmus_mujoco_error(const char* message) { mju_error("%s", message); }
void actuator_fmus_mujoco_warning(const char* message) { mju_warning("%s", message); }
