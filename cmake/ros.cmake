# ROS recordings for `wheelins import` (src/wheelins/io/ros/): ROS 1 bags (our reader, with
# bzip2 and lz4 for compressed chunks), ROS 2 bags in sqlite3 and MCAP (our readers, with zstd
# and lz4 for compressed MCAP chunks). All are Debian packages that scripts/setup.sh installs.
# (The tests write ROS 1 bags with the ROS bag storage library: cmake/ros_tests.cmake.)
set(_wheelins_ros_hint "install the packages with scripts/setup.sh (libsqlite3-dev, libzstd-dev, \
liblz4-dev, libbz2-dev)")
find_package(SQLite3)
find_path(WHEELINS_ZSTD_INCLUDE zstd.h)
find_library(WHEELINS_ZSTD_LIB zstd)
find_path(WHEELINS_LZ4_INCLUDE lz4frame.h)
find_library(WHEELINS_LZ4_LIB lz4)
find_path(WHEELINS_BZ2_INCLUDE bzlib.h)
find_library(WHEELINS_BZ2_LIB bz2)
foreach(v WHEELINS_ZSTD_INCLUDE WHEELINS_ZSTD_LIB WHEELINS_LZ4_INCLUDE WHEELINS_LZ4_LIB WHEELINS_BZ2_INCLUDE
          WHEELINS_BZ2_LIB)
  if(NOT ${v} OR "${${v}}" MATCHES "NOTFOUND")
    message(FATAL_ERROR "wheelins import: ${v} not found; ${_wheelins_ros_hint}")
  endif()
endforeach()
if(NOT SQLite3_FOUND)
  message(FATAL_ERROR "wheelins import: sqlite3 not found; ${_wheelins_ros_hint}")
endif()

target_include_directories(wheelins_io SYSTEM PRIVATE ${WHEELINS_ZSTD_INCLUDE} ${WHEELINS_LZ4_INCLUDE}
                           ${WHEELINS_BZ2_INCLUDE})
target_link_libraries(wheelins_io PUBLIC SQLite::SQLite3 ${WHEELINS_ZSTD_LIB} ${WHEELINS_LZ4_LIB} ${WHEELINS_BZ2_LIB})
