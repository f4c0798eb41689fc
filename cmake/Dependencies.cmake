# Every external dependency of SpriteStation is found here and nowhere else.
# All of them come from Debian packages installed by scripts/install-deps.sh.
find_package(PkgConfig REQUIRED)
find_package(Threads REQUIRED)

find_package(OpenCV 4 REQUIRED COMPONENTS core imgproc imgcodecs calib3d video features2d objdetect aruco)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(yaml-cpp REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(spdlog REQUIRED)
pkg_check_modules(HTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)

pkg_check_modules(SQLITE3 REQUIRED IMPORTED_TARGET sqlite3)
pkg_check_modules(LIBPQ REQUIRED IMPORTED_TARGET libpq)
pkg_check_modules(FFMPEG REQUIRED IMPORTED_TARGET libavformat libavcodec libavutil libswscale libavfilter)
pkg_check_modules(ZSTD REQUIRED IMPORTED_TARGET libzstd)
pkg_check_modules(SYSTEMD IMPORTED_TARGET libsystemd)

# mrcal ships no pkg-config file on Debian: headers in /usr/include/mrcal, libmrcal.so.
find_path(MRCAL_INCLUDE_DIR mrcal.h PATH_SUFFIXES mrcal REQUIRED)
find_library(MRCAL_LIBRARY mrcal REQUIRED)
add_library(mrcal::mrcal UNKNOWN IMPORTED)
set_target_properties(mrcal::mrcal PROPERTIES
  IMPORTED_LOCATION "${MRCAL_LIBRARY}"
  INTERFACE_INCLUDE_DIRECTORIES "${MRCAL_INCLUDE_DIR}")

# A camera backend whose library the machine may lack: PkgConfig::NAME when its module is
# found, else SPRITESTATION_NAME turned off with a word why.
macro(spritestation_optional_backend NAME MODULE LABEL)
  if(SPRITESTATION_${NAME})
    pkg_check_modules(${NAME} IMPORTED_TARGET ${MODULE})
    if(NOT ${NAME}_FOUND)
      message(STATUS "${LABEL} backend: skipped (${MODULE} not found)")
      set(SPRITESTATION_${NAME} OFF)
    endif()
  endif()
endmacro()
spritestation_optional_backend(ARAVIS aravis-0.8 Aravis)
spritestation_optional_backend(LIBCAMERA libcamera libcamera)

if(SPRITESTATION_TESTS)
  find_package(GTest REQUIRED)
endif()
if(SPRITESTATION_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
