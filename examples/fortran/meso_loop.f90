! A meso-side contact loop in Fortran with OpenMP, as examples/c/meso_loop.c: every increment each
! thread gathers its sub-domain's contact points into one block, makes one call on the handle all
! threads share, applies tau = mu * p and flags points whose 95 % interval is wide. Run with one
! thread and with two at once; checks lo <= mu <= hi, status OK, and that both runs agree to the
! last bit.   meso_loop URI [increments] [points_per_domain] [options, e.g. 'stream=1']
program meso_loop
  use, intrinsic :: iso_c_binding
  use omp_lib
  use mufric
  implicit none
  integer, parameter :: domains = 2
  real(c_double), parameter :: contact_length = 0.2d-3, wide = 0.05d0
  real(c_double), allocatable, target :: p(:, :), v(:, :), t(:, :), mu(:, :), lo(:, :), hi(:, :)
  integer(c_int), allocatable, target :: status(:, :)
  real(c_double) :: force(domains), total(2), seconds
  integer :: flagged(domains), bad(domains), flags(2), bads(2)
  type(c_ptr) :: client
  character(len=512) :: uri, argument, options
  integer :: n, increments, pass, increment, i, k, failed
  real(c_double) :: s, breathing, dx

  call get_command_argument(1, uri)
  increments = 50
  n = 1000
  if (command_argument_count() >= 2) then
    call get_command_argument(2, argument)
    read (argument, *) increments
  end if
  if (command_argument_count() >= 3) then
    call get_command_argument(3, argument)
    read (argument, *) n
  end if
  options = ''
  if (command_argument_count() >= 4) call get_command_argument(4, options)
  if (mufric_connect(uri, client, options) /= MUFRIC_OK) then
    print *, 'mufric_connect: ', mufric_error()
    stop 2
  end if
  allocate (p(n, domains), v(n, domains), t(n, domains), mu(n, domains), lo(n, domains), hi(n, domains), &
            status(n, domains))
  dx = contact_length / domains / n
  failed = 0

  do pass = 1, 2
    force = 0
    flagged = 0
    bad = 0
    seconds = omp_get_wtime()
    do increment = 0, increments - 1
      breathing = 1.0d0 + 0.05d0 * sin(0.1d0 * increment)
      !$omp parallel do num_threads(pass) schedule(static, 1) private(k, s)
      do i = 1, domains
        do k = 1, n   ! gather: the contact state of this sub-domain's points
          s = ((i - 1) + (k - 0.5d0) / n) / domains
          p(k, i) = (320.0d6 + 850.0d6 * (1.0d0 - s)**1.5d0) * breathing
          v(k, i) = 0.5d0 + 2.5d0 * s
          t(k, i) = 473.15d0 + 600.0d0 * s * (1.0d0 - 0.4d0 * s)
        end do
        if (c_mufric_evaluate(client, int(n, c_size_t), c_loc(p(1, i)), c_loc(v(1, i)), c_loc(t(1, i)), c_null_ptr, &
                              0.95d0, c_loc(mu(1, i)), c_null_ptr, c_loc(lo(1, i)), c_loc(hi(1, i)), &
                              c_loc(status(1, i))) /= MUFRIC_OK) then
          !$omp critical
          print *, 'mufric_evaluate: ', mufric_error()
          failed = 1
          !$omp end critical
        else
          do k = 1, n
            force(i) = force(i) + mu(k, i) * p(k, i) * dx
            if (0.5d0 * (hi(k, i) - lo(k, i)) > wide * mu(k, i)) flagged(i) = flagged(i) + 1
            if (.not. (lo(k, i) <= mu(k, i) .and. mu(k, i) <= hi(k, i)) .or. status(k, i) /= MUFRIC_POINT_OK) &
              bad(i) = bad(i) + 1
          end do
        end if
      end do
      !$omp end parallel do
      if (failed /= 0) stop 1
    end do
    seconds = omp_get_wtime() - seconds
    print '(i2, a, f9.3, a, i6, a)', pass, ' thread(s): ', 1.0d3 * seconds / increments, ' ms per increment of ', &
          domains * n, ' points'
    total(pass) = force(1) + force(2)   ! fixed order: bitwise comparable
    flags(pass) = sum(flagged)
    bads(pass) = sum(bad)
  end do
  call c_mufric_close(client)

  print '(a, es14.6, a, i8, a)', 'mean friction force', total(1) / increments, ' N/m per increment;', flags(1), &
        ' points flagged'
  if (sum(bads) > 0) then
    print *, sum(bads), 'points outside their own interval or not OK'
    stop 1
  end if
  if (total(1) /= total(2) .or. flags(1) /= flags(2)) then
    print *, 'two threads changed the answer: ', total(1), total(2), flags(1), flags(2)
    stop 1
  end if
  if (.not. (total(1) > 0)) stop 1
  print *, 'one and two threads agree to the last bit'
end program
