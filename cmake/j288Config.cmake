# find_package(j288 REQUIRED), then target_link_libraries(app PRIVATE j288::j288): the static
# library with its headers and the J288_CONFIG_* definitions it was built with; on Linux also
# j288::robot, libj288.so (the library, the Linux port, the config reader and the multi-bus
# runner; #include "j288_robot.h"), which holds the library too: link one of the two.
include("${CMAKE_CURRENT_LIST_DIR}/j288Targets.cmake")
