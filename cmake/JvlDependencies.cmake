# All third-party dependencies come from Debian packages (scripts/install_deps.sh).
find_package(Threads REQUIRED)
find_package(Eigen3 3.3 REQUIRED NO_MODULE)
find_package(OpenCV REQUIRED COMPONENTS core imgproc imgcodecs features2d calib3d)
# The Fast Line Detector lives in opencv_contrib's ximgproc (Debian: libopencv-contrib-dev).
# Optional: without it the vision library offers the LSD line detector only.
find_package(OpenCV QUIET COMPONENTS ximgproc)
if(TARGET opencv_ximgproc)
  set(JVL_HAVE_XIMGPROC ON)
else()
  set(JVL_HAVE_XIMGPROC OFF)
  message(STATUS "opencv_ximgproc not found: only the LSD line detector is available")
endif()
find_package(Ceres REQUIRED)
# glog comes with Ceres (it logs through it); the tools silence it (app/tool.cc).
find_package(glog CONFIG REQUIRED)
find_package(nlohmann_json 3 REQUIRED)
find_package(spdlog REQUIRED)
find_package(CLI11 CONFIG REQUIRED)
find_package(HDF5 REQUIRED COMPONENTS C)
find_package(PCL REQUIRED COMPONENTS common kdtree search filters sample_consensus segmentation)

# PCL's config adds global definitions and include dirs; keep them on an imported target instead.
add_library(jvl_pcl INTERFACE)
target_include_directories(jvl_pcl SYSTEM INTERFACE ${PCL_INCLUDE_DIRS})
target_link_libraries(jvl_pcl INTERFACE ${PCL_LIBRARIES})

add_library(jvl_hdf5 INTERFACE)
target_include_directories(jvl_hdf5 SYSTEM INTERFACE ${HDF5_C_INCLUDE_DIRS} ${HDF5_INCLUDE_DIRS})
target_link_libraries(jvl_hdf5 INTERFACE ${HDF5_C_LIBRARIES})
target_compile_definitions(jvl_hdf5 INTERFACE ${HDF5_C_DEFINITIONS} ${HDF5_DEFINITIONS})

add_library(jvl_opencv INTERFACE)
target_include_directories(jvl_opencv SYSTEM INTERFACE ${OpenCV_INCLUDE_DIRS})
target_link_libraries(jvl_opencv INTERFACE ${OpenCV_LIBS})

if(JVL_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(JVL_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()
