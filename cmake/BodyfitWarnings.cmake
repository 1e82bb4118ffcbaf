# Warnings are part of the code's quality: every target of the project uses these.
function(bodyfit_warnings target)
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic)
endfunction()
